"""The product's loaded level over the other knob's angle, read on the sheet's unit
(tsmd.datasheet_level_grid)."""

from __future__ import annotations

import dataclasses

import pytest
from support.tracked import tracked_sweeps

from tsmd.compensation.level_grid import LevelGrid
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.datasheet_level_grid import MIN_LEVEL_SHIFT_DEG, TrackedSweep, level_grid

ANGLES = (-60.0, 0.0, 60.0)


def tension() -> TensionPlayParams:
    return TensionPlayParams(1.3, -2.0, 2.0, ANGLES, (20.0,) * 3, (-20.0,) * 3, (0.1,) * 3,
                             (0.1,) * 3, (-60.0,) * 3, (60.0,) * 3)


def sweeps_of(truth: TensionPlayParams) -> list[tuple[float, TrackedSweep]]:
    """Two sweeps per angle, the other knob held there."""
    return tracked_sweeps(truth, ANGLES, repeats=2)


def test_the_grid_finds_the_level_the_tip_stands_at() -> None:
    shifted = LevelGrid(ANGLES, (-2.0, 0.0, -3.0), (2.5, 0.0, 1.5))
    found = level_grid(sweeps_of(dataclasses.replace(tension(), level_grid=shifted)), tension())
    assert found is not None
    assert found.other_knob_deg == ANGLES
    assert found.pos_deg == pytest.approx(shifted.pos_deg, abs=0.3)
    assert found.neg_deg == pytest.approx(shifted.neg_deg, abs=0.3)


def test_a_tip_on_the_model_gives_no_grid() -> None:
    assert level_grid(sweeps_of(tension()), tension()) is None


def test_a_shift_below_the_threshold_is_none() -> None:
    small = 0.5 * MIN_LEVEL_SHIFT_DEG
    shifted = LevelGrid(ANGLES, (-small, 0.0, -3.0), (small, 0.0, 1.5))
    found = level_grid(sweeps_of(dataclasses.replace(tension(), level_grid=shifted)), tension())
    assert found is not None
    assert (found.pos_deg[0], found.neg_deg[0]) == (0.0, 0.0)


def test_without_a_sweep_at_the_other_knobs_zero_there_is_no_grid() -> None:
    shifted = LevelGrid(ANGLES, (-2.0, 0.0, -3.0), (2.5, 0.0, 1.5))
    sweeps = [s for s in sweeps_of(dataclasses.replace(tension(), level_grid=shifted))
              if s[0] != 0.0]
    assert level_grid(sweeps, tension()) is None


def test_an_angle_where_the_profile_is_mis_read_is_left_out() -> None:
    shifted = LevelGrid(ANGLES, (-2.0, 0.0, -3.0), (2.5, 0.0, 1.5))
    misread = dataclasses.replace(tension(), dead_zone_pos_deg=(1.0, 20.0, 20.0))
    found = level_grid(sweeps_of(dataclasses.replace(tension(), level_grid=shifted)), misread)
    assert found is not None
    assert found.other_knob_deg == (0.0, 60.0)
    assert found.pos_deg == pytest.approx((0.0, -3.0), abs=0.3)


WIDE = (-90.0, -60.0, -30.0, 0.0, 30.0, 60.0, 90.0)


def wide_tension() -> TensionPlayParams:
    return TensionPlayParams(1.3, -2.0, 2.0, WIDE, (20.0,) * 7, (-20.0,) * 7, (0.1,) * 7,
                             (0.1,) * 7, (-60.0,) * 7, (60.0,) * 7)


def test_a_large_level_growing_with_the_other_knobs_angle_is_kept() -> None:
    # pronyring's pull ring: the other plane's load holds the tip 11-17 deg off at +-90
    shifted = LevelGrid(WIDE, (-14.0, -7.0, -1.5, 0.0, -1.5, -7.0, -14.0),
                        (13.0, 6.0, 1.5, 0.0, 1.5, 6.0, 13.0))
    truth = dataclasses.replace(wide_tension(), level_grid=shifted)
    found = level_grid(tracked_sweeps(truth, WIDE), wide_tension())
    assert found is not None
    assert found.other_knob_deg == WIDE
    assert found.pos_deg == pytest.approx(shifted.pos_deg, abs=0.3)
    assert found.neg_deg == pytest.approx(shifted.neg_deg, abs=0.3)


def test_one_mis_read_angle_among_a_large_level_is_left_out_alone() -> None:
    shifted = LevelGrid(WIDE, (-14.0, -8.0, -3.0, 0.0, -3.0, -8.0, -14.0),
                        (13.0, 8.0, 3.0, 0.0, 3.0, 8.0, 13.0))
    misread = dataclasses.replace(wide_tension(),
                                  dead_zone_pos_deg=(20.0, 20.0, 20.0, 20.0, 20.0, 1.0, 20.0))
    truth = dataclasses.replace(wide_tension(), level_grid=shifted)
    found = level_grid(tracked_sweeps(truth, WIDE), misread)
    assert found is not None
    assert found.other_knob_deg == (-90.0, -60.0, -30.0, 0.0, 30.0, 90.0)
    assert found.pos_deg[-1] == pytest.approx(-14.0, abs=0.3)
