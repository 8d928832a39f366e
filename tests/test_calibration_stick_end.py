"""The stick phase's end after a reversal (`tsmd.calibration.stick_end`) and its choice on the
data sheet's unit (`tsmd.datasheet_stick_end`)."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest
from support.profiles import DEVICE, assert_sheet_knob_field_round_trips

import tsmd.datasheet_stick_end as stick_end
from tsmd.calibration.identify import unit_share_backlash
from tsmd.calibration.options import IdentifyOptions, device_options
from tsmd.calibration.stick_end import STICK_SLOPE_SHARE, stick_end_index
from tsmd.calibration.sweep_result import HalfCycle
from tsmd.datasheet_stick_end import half_scatter_deg, stick_choice, with_stick_end
from tsmd.profile import load_device_model

STEP_DEG = 0.25


def after_reversal(stick_deg: float, creep_per_deg: float = 0.001) -> tuple[np.ndarray,
                                                                            np.ndarray]:
    """A direction-signed current after a reversal: a steep fall (0.02 A per deg) for
    ``stick_deg``, then a creep that fades over 6 deg, then a flat release level."""
    grid = np.arange(0.0, 60.0, STEP_DEG)
    steep = -0.1 + 0.02 * np.minimum(grid, stick_deg)
    beyond = np.maximum(grid - stick_deg, 0.0)
    creep = creep_per_deg * 6.0 * (1.0 - np.exp(-beyond / 6.0))
    return grid, steep + creep


def test_the_stick_end_is_where_the_steep_fall_levels_off() -> None:
    for stick_deg in (5.0, 8.0):
        grid, y = after_reversal(stick_deg)
        k = stick_end_index(grid, y)
        assert k is not None
        assert abs(grid[k] - stick_deg) <= 2.0


def test_the_creep_after_the_stick_phase_does_not_move_the_end() -> None:
    grid, slow = after_reversal(6.0, creep_per_deg=0.0005)
    _, fast = after_reversal(6.0, creep_per_deg=0.002)
    a, b = stick_end_index(grid, slow), stick_end_index(grid, fast)
    assert a is not None and b is not None
    assert abs(grid[a] - grid[b]) <= 0.5


def test_a_current_that_never_falls_steeply_has_no_stick_end() -> None:
    grid = np.arange(0.0, 60.0, STEP_DEG)
    assert stick_end_index(grid, np.full(grid.size, 0.01)) is None
    assert stick_end_index(grid, -0.001 * grid) is None


def test_the_share_is_of_the_steepest_slope_not_an_absolute_one() -> None:
    grid, y = after_reversal(6.0)
    k1, k2 = stick_end_index(grid, y), stick_end_index(grid, 10.0 * y)
    assert k1 == k2
    assert 0.0 < STICK_SLOPE_SHARE < 0.5


def test_the_sheets_stick_end_turns_the_option_on_for_its_knob_only() -> None:
    device = with_stick_end(load_device_model(DEVICE), (False, True))
    phi1, phi2 = device_options(None, device)
    assert (phi1.backlash_stick_end, phi2.backlash_stick_end) == (False, True)
    assert not IdentifyOptions().backlash_stick_end


def test_with_the_stick_end_no_unit_share_moves_a_half_cycles_end() -> None:
    opts = dataclasses.replace(IdentifyOptions(), backlash="fraction",
                               backlash_reference_slope_ratio=0.2, backlash_stick_end=True)
    halves = (HalfCycle(1, 0, 10, True, backlash_deg=7.0),)
    assert unit_share_backlash(None, halves, opts) is halves  # type: ignore[arg-type]


def test_the_stick_end_and_the_settle_reading_fields_round_trip() -> None:
    assert_sheet_knob_field_round_trips("backlash_stick_end", 1, True, "yes")  # type: ignore[arg-type]
    assert_sheet_knob_field_round_trips("settle_gain_read", 0, False, "no")  # type: ignore[arg-type]


def _run(values: dict[tuple[int, float], dict[str, tuple[float, ...]]]) -> SimpleNamespace:
    points = [SimpleNamespace(knob=k, other_deg=o, result=SimpleNamespace(values=v, unseen={}))
              for (k, o), v in values.items()]
    return SimpleNamespace(points=points)


def test_the_scatter_is_about_each_grid_points_own_offset() -> None:
    truth = {(0, 0.0): {"backlash_pos_deg": 8.0}, (0, 90.0): {"backlash_pos_deg": 9.0}}
    offset_only = _run({(0, 0.0): {"backlash_pos_deg": (6.5, 6.5)},
                        (0, 90.0): {"backlash_pos_deg": (12.0, 12.0)}})
    scattered = _run({(0, 0.0): {"backlash_pos_deg": (7.0, 9.0)},
                      (0, 90.0): {"backlash_pos_deg": (9.0, 9.0)}})
    assert half_scatter_deg([offset_only], truth, 0) == (pytest.approx(0.0), 4)  # type: ignore[list-item]
    rms, n = half_scatter_deg([scattered], truth, 0)  # type: ignore[list-item]
    assert n == 4 and rms == pytest.approx(math.sqrt(2.0 / 4.0))


def test_the_stick_end_is_chosen_only_where_it_scatters_less_by_more_than_the_angle_grid(
        ) -> None:
    assert stick_choice((1.7, 24), (0.3, 24))
    assert not stick_choice((0.3, 24), (0.3, 24))
    assert not stick_choice((0.14, 12), (0.10, 12))
    assert not stick_choice((0.3, 24), (1.0, 24))
    assert not stick_choice((1.7, 24), (math.nan, 0))


def test_the_rule_gain_is_read_again_only_where_the_stick_end_is_on(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(stick_end, "rule_backlash_gain", lambda points, knob: 0.09 + knob)
    base = load_device_model(DEVICE)
    knobs = tuple(dataclasses.replace(k, reference_rule_backlash_gain=0.117) for k in base.knobs)
    device = dataclasses.replace(base, knobs=knobs)
    runs = [SimpleNamespace(points=[])]
    out = stick_end.with_rule_gain(device, runs, (True, False))  # type: ignore[arg-type]
    assert [k.reference_rule_backlash_gain for k in out.knobs] == [0.09, 0.117]
