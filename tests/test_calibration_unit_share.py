"""The fraction rule's share per unit: each sweep's release-to-loaded slope ratio moves the data
sheet's share (docs/calibration.md, session 8)."""

from __future__ import annotations

from dataclasses import replace
from functools import cache

import numpy as np
import pytest

from tsmd.calibration.identify import analyse_half_cycle, split_half_cycles, unit_share_backlash
from tsmd.calibration.options import SHARE_PER_SLOPE_RATIO, IdentifyOptions, for_product
from tsmd.calibration.release import release_slope_ratio
from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import HalfCycle

LOADED_SLOPE_A_PER_DEG = 0.02
EDGE_TRAVEL_DEG = 120.0


def _release_curve(travel_deg: np.ndarray, release_slope: float) -> np.ndarray:
    """Direction-signed current after a reversal: an approach from -1 A to a release level that
    rises at ``release_slope`` A/deg, then the loaded ramp past the dead-zone edge."""
    level = 0.1 + release_slope * travel_deg
    approach = level - 1.1 * np.exp(-travel_deg / 3.0)
    return approach + LOADED_SLOPE_A_PER_DEG * np.maximum(travel_deg - EDGE_TRAVEL_DEG, 0.0)


PLAIN = replace(IdentifyOptions(), backlash="fraction", backlash_fraction=0.95)


@cache
def _unit(release_slope: float) -> tuple[Conditioned, tuple[HalfCycle, ...]]:
    """Knob 60 -> 90 -> -90 deg at 10 deg/s, 10 samples per degree, current noise-free; its
    half-cycles analysed with the sheet's share alone (the change-point search runs once)."""
    up = np.linspace(60.0, 90.0, 301)
    down = np.linspace(90.0, -90.0, 1801)[1:]
    pos = np.concatenate([up, down])
    t = np.arange(pos.size) * 1e-2
    current = np.concatenate([np.linspace(0.9, 1.0, up.size),
                              -_release_curve(90.0 - down, release_slope)])
    data = Conditioned(t, pos, pos, current, current, 100.0, 0.001, 0.0005, ())
    halves = tuple(analyse_half_cycle(data, d, a, b, r, PLAIN)
                   for d, a, b, r in split_half_cycles(data.cmd_deg, 10.0))
    return data, halves


def _backlash(opts: IdentifyOptions, release_slope: float = 0.001) -> float:
    data, halves = _unit(release_slope)
    after = [h for h in unit_share_backlash(data, halves, opts) if h.after_reversal]
    assert len(after) == 1
    return after[0].backlash_deg


def test_the_slope_ratio_is_the_release_levels_slope_over_the_loaded_ramps() -> None:
    grid = np.arange(0.0, 177.0, 0.25)
    ratio = release_slope_ratio(grid, _release_curve(grid, 0.001), round(30.0 / 0.25))
    assert ratio == pytest.approx(0.001 / (LOADED_SLOPE_A_PER_DEG + 0.001), rel=0.02)


def test_a_sheet_with_a_slope_ratio_moves_the_share_per_unit() -> None:
    opts = for_product(IdentifyOptions(), 0.95, slope_ratio=0.06)
    assert opts.backlash_reference_slope_ratio == 0.06
    assert opts.backlash_share_per_slope_ratio == SHARE_PER_SLOPE_RATIO < 0.0


def test_a_sheet_without_a_slope_ratio_keeps_one_share_for_every_unit() -> None:
    opts = for_product(IdentifyOptions(), 0.95)
    assert opts.backlash_reference_slope_ratio is None
    data, halves = _unit(0.001)
    assert unit_share_backlash(data, halves, opts) == halves


def test_a_unit_with_the_sheets_slope_ratio_keeps_the_sheets_share() -> None:
    grid = np.arange(0.0, 177.0, 0.25)
    k = round(_backlash(PLAIN) / 0.25)
    own = replace(PLAIN, backlash_reference_slope_ratio=release_slope_ratio(
        grid, _release_curve(grid, 0.001), k),
        backlash_share_per_slope_ratio=SHARE_PER_SLOPE_RATIO)
    assert _backlash(own) == pytest.approx(_backlash(PLAIN), abs=0.25)


@pytest.mark.parametrize(("sheet_ratio", "later"), [(0.2, True), (-0.1, False)])
def test_a_flatter_release_than_the_sheets_ends_the_backlash_later(sheet_ratio: float,
                                                                  later: bool) -> None:
    # this unit's ratio is 0.05: a sheet unit with a steeper release (0.2) let go earlier in
    # its current's approach, so this unit's share is higher and its backlash ends later
    moved = replace(PLAIN, backlash_reference_slope_ratio=sheet_ratio,
                    backlash_share_per_slope_ratio=SHARE_PER_SLOPE_RATIO)
    shift = _backlash(moved) - _backlash(PLAIN)
    assert (shift > 1.0) if later else (shift < -1.0)


def test_the_slope_ratio_stops_before_a_dead_zone_edge_inside_its_window() -> None:
    # an edge 30 deg after the release end: past it the current is the loaded ramp, whose
    # slope would be read as the release level's
    grid = np.arange(0.0, 177.0, 0.25)
    k = round(30.0 / 0.25)
    curve = _release_curve(grid, 0.001) + LOADED_SLOPE_A_PER_DEG * np.maximum(grid - 60.0, 0.0)
    stop = round(57.0 / 0.25)
    release_level_only = 0.001 / (2.0 * LOADED_SLOPE_A_PER_DEG + 0.001)
    assert release_slope_ratio(grid, curve, k, stop) == pytest.approx(release_level_only,
                                                                      rel=0.05)
    assert release_slope_ratio(grid, curve, k) > 2.0 * release_level_only
