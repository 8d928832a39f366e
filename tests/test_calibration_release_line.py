"""The fraction rule against the release line: the share of the gap to the release branch at
the same knob angle, the branch fitted once per half-cycle (docs/calibration.md, session 10)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq

from tsmd.calibration.identify import analyse_half_cycle, split_half_cycles
from tsmd.calibration.options import IdentifyOptions, for_product
from tsmd.calibration.release import (
    fraction_end,
    line_share_at,
    line_share_end,
    local_share_at,
    local_share_end,
    release_line,
    share_end,
)
from tsmd.calibration.signal import Conditioned
from tsmd.profile import load_device_model
from tsmd.profile.sheet_schema import device_model_from_mapping, device_model_to_mapping

DEVICE = "profiles/devices/sim-catheter.yaml"

STEP_DEG = 0.25
GRID = np.arange(0.0, 100.0, STEP_DEG)
GAP_A = 0.08
"""The current's jump after a reversal, from the loaded current to the release branch."""
TAU_DEG = 5.0
SHARE = 0.946


def _release(slope_A_per_deg: float) -> np.ndarray:
    """Direction-signed current after a reversal: an exponential approach to a release branch
    that climbs at ``slope_A_per_deg`` (the segments plant: 0.5-0.8 % of the swing per deg)."""
    return 0.1 + slope_A_per_deg * GRID - GAP_A * np.exp(-GRID / TAU_DEG)


def _tip_release_deg(slope_A_per_deg: float) -> float:
    """Where a synthetic tip lets go: the current has closed ``SHARE`` of its gap to the branch
    at the same angle."""
    def gap_left(x: float) -> float:
        return GAP_A * np.exp(-x / TAU_DEG) - (1.0 - SHARE) * (GAP_A + slope_A_per_deg * x)
    return float(brentq(gap_left, 0.0, 60.0))


@pytest.mark.parametrize("slope_share_per_deg", [0.005, 0.008])
def test_a_sloped_release_branch_ends_where_the_tip_lets_go(slope_share_per_deg: float) -> None:
    slope = slope_share_per_deg * GAP_A
    y = _release(slope)
    line = release_line(GRID, y)
    assert line is not None
    k = line_share_end(GRID, y, line, SHARE, 4.0)
    assert GRID[k] == pytest.approx(_tip_release_deg(slope), abs=0.5)


def test_on_a_flat_release_level_the_line_gives_the_median_levels_end() -> None:
    y = _release(0.0)
    line = release_line(GRID, y)
    assert line is not None
    settled = round(30.0 / STEP_DEG)
    assert line_share_end(GRID, y, line, SHARE, 4.0) == pytest.approx(
        share_end(GRID, y, settled, SHARE, 4.0), abs=1)


def test_the_sheets_line_share_is_what_the_end_inverts() -> None:
    y = _release(0.006 * GAP_A)
    line = release_line(GRID, y)
    assert line is not None
    k = line_share_end(GRID, y, line, SHARE, 4.0)
    assert line_share_at(GRID, y, k, line, 4.0) == pytest.approx(SHARE, abs=0.003)


def test_a_half_cycle_too_short_for_the_line_keeps_the_median_level() -> None:
    short = GRID < 45.0
    y = _release(0.0)[short]
    opts = replace(IdentifyOptions(), backlash="fraction", backlash_fraction=SHARE,
                   release_level="line")
    assert release_line(GRID[short], y) is None
    settled = round(30.0 / STEP_DEG)
    assert fraction_end(GRID[short], y, settled, SHARE, opts) == share_end(
        GRID[short], y, settled, SHARE, 4.0)


def test_the_line_ends_before_a_dead_zone_edge_inside_its_window() -> None:
    y = _release(0.0) + 0.02 * np.maximum(GRID - 60.0, 0.0)
    stop = round(57.0 / STEP_DEG)
    line = release_line(GRID, y, stop)
    assert line is not None
    assert line[0] == pytest.approx(0.0, abs=1e-5)
    assert release_line(GRID, y)[0] > 1e-3  # type: ignore[index]


def test_a_sheet_with_a_line_share_ends_the_backlash_against_the_line() -> None:
    opts = for_product(IdentifyOptions(), 0.95, slope_ratio=0.1, line_share=0.94)
    assert (opts.backlash, opts.release_level, opts.backlash_fraction) == (
        "fraction", "line", 0.94)
    assert opts.backlash_reference_slope_ratio == 0.1


def test_a_settled_line_share_keeps_the_settle_rule_with_its_lag() -> None:
    opts = for_product(IdentifyOptions(), 0.95, line_share=0.995, settle_lag_deg=0.7)
    assert (opts.backlash, opts.backlash_settle_lag_deg) == ("settle", 0.7)


def test_a_sweep_on_a_sloped_branch_ends_its_backlash_where_the_tip_lets_go() -> None:
    # through the half-cycle analysis: knob 90 -> -90 deg after a reversal, 10 samples per deg
    slope = 0.006 * GAP_A
    down = np.linspace(90.0, -90.0, 1801)
    travel = 90.0 - down
    # continuous at the reversal: the loaded current is the last one before it
    current = -(GAP_A - 1.0 + slope * travel - GAP_A * np.exp(-travel / TAU_DEG)
                + 0.02 * np.maximum(travel - 120.0, 0.0))
    pos = np.concatenate([np.linspace(60.0, 90.0, 301), down[1:]])
    current = np.concatenate([np.linspace(0.9, 1.0, 301), current[1:]])
    data = Conditioned(np.arange(pos.size) * 1e-2, pos, pos, current, current, 100.0, 5e-4,
                       2.5e-4, ())
    opts = replace(IdentifyOptions(), backlash="fraction", backlash_fraction=SHARE,
                   release_level="line")
    d, a, b, after = split_half_cycles(data.cmd_deg, 10.0)[-1]
    h = analyse_half_cycle(data, d, a, b, after, opts)
    assert h.backlash_deg == pytest.approx(_tip_release_deg(slope), abs=0.5)


def test_the_line_share_survives_the_sheets_yaml() -> None:
    mapping = device_model_to_mapping(load_device_model(DEVICE))
    mapping["knobs"]["phi1"]["backlash_release_line_share"] = 0.9437
    sheet = device_model_from_mapping(mapping)
    assert sheet.knobs[0].backlash_release_line_share == 0.9437
    assert sheet.knobs[1].backlash_release_line_share is None
    assert device_model_to_mapping(sheet)["knobs"]["phi1"]["backlash_release_line_share"] == 0.9437


def shelf_then_ramp(x_deg: np.ndarray) -> np.ndarray:
    """A release that levels off on a shelf 14 deg after the reversal and ramps on from 30 to
    60 deg (the coilpipe plant's shape), direction-signed: loaded -1 A, final level 0 A."""
    fall = 0.85 * (1.0 - np.exp(-x_deg / 3.5))
    ramp = 0.15 * np.clip((x_deg - 30.0) / 30.0, 0.0, 1.0)
    return np.asarray(-1.0 + fall + ramp, dtype=float)


def test_the_local_rule_ends_on_the_shelf_not_on_the_later_ramp() -> None:
    grid = np.arange(0.0, 100.0, 0.25)
    y = shelf_then_ramp(grid)
    release = round(14.0 / 0.25)
    share = local_share_at(grid, y, release, 4.0)
    assert local_share_end(grid, y, share, 4.0) == pytest.approx(release, abs=4)

