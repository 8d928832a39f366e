"""The tip's loaded level against the current's edge over the other knob's angle: the unit's
grid from the product's share (tsmd.calibration.edge_level) and the share read on the sheet's
unit (tsmd.datasheet_edge_level)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from support.profiles import assert_sheet_knob_field_round_trips
from support.tracked import tracked_sweeps
from test_compensation_tension_play_fit import DEVICE_KNOB, synthetic_sweep

from tsmd.calibration.edge_level import edge_level_grid, edge_level_shifts
from tsmd.calibration.tension_play_fit import fit_tension_play
from tsmd.compensation.level_grid import LEVEL_SHIFT_RANGE_DEG, LevelGrid
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.datasheet_edge_level import MIN_EDGE_LEVEL_GAIN_DEG, edge_share, fit_share
from tsmd.datasheet_level_grid import TrackedSweep

ANGLES = (-90.0, 0.0, 90.0)
D_POS = (17.0, 24.0, 19.0)
D_NEG = (-19.0, -24.0, -18.0)


def test_share_zero_leaves_every_level_where_the_edge_puts_it() -> None:
    grid = edge_level_grid(0.0, 1.4, ANGLES, D_POS, D_NEG)
    assert grid is not None
    assert grid.pos_deg == (0.0, 0.0, 0.0)
    assert grid.neg_deg == (0.0, 0.0, 0.0)


def test_an_edge_moved_inward_moves_its_side_inward_by_the_share_of_omega() -> None:
    grid = edge_level_grid(0.8, 1.5, ANGLES, D_POS, D_NEG)
    assert grid is not None
    assert grid.pos_deg == pytest.approx((0.8 * 1.5 * -7.0, 0.0, 0.8 * 1.5 * -5.0))
    assert grid.neg_deg == pytest.approx((0.8 * 1.5 * 5.0, 0.0, 0.8 * 1.5 * 6.0))


def test_a_shift_is_held_inside_the_level_grids_range() -> None:
    lo, hi = LEVEL_SHIFT_RANGE_DEG
    shifts = edge_level_shifts(1.5, 1.5, ANGLES, (-40.0, 24.0, 80.0))
    assert shifts == (lo, 0.0, hi)


def test_a_share_outside_its_range_is_refused_in_one_line() -> None:
    with pytest.raises(ValueError, match="edge_level_share 2.0 outside"):
        edge_level_grid(2.0, 1.4, ANGLES, D_POS, D_NEG)


def test_the_products_own_level_grid_is_added_at_the_units_angles() -> None:
    product = LevelGrid((-90.0, 90.0), (-1.0, -3.0), (2.0, 4.0))
    alone = edge_level_grid(1.0, 1.0, ANGLES, D_POS, D_NEG)
    both = edge_level_grid(1.0, 1.0, ANGLES, D_POS, D_NEG, product)
    assert alone is not None and both is not None
    assert np.subtract(both.pos_deg, alone.pos_deg) == pytest.approx((-1.0, -2.0, -3.0))
    assert np.subtract(both.neg_deg, alone.neg_deg) == pytest.approx((2.0, 3.0, 4.0))


def test_calibration_turns_the_sheets_share_into_the_units_own_level_grid() -> None:
    sweeps = [dataclasses.replace(synthetic_sweep(a), dead_zone_pos_deg=d)
              for a, d in zip(ANGLES, (16.0, 20.0, 17.0), strict=True)]
    plain = fit_tension_play(sweeps, DEVICE_KNOB)
    shared = fit_tension_play(sweeps, dataclasses.replace(DEVICE_KNOB, edge_level_share=0.9))
    assert plain.level_grid is None
    assert shared.level_grid == edge_level_grid(0.9, plain.omega, plain.other_knob_deg,
                                                plain.dead_zone_pos_deg,
                                                plain.dead_zone_neg_deg)
    assert shared.level_grid is not None and min(shared.level_grid.pos_deg) < 0.0
    assert shared == dataclasses.replace(plain, level_grid=shared.level_grid)


def test_the_data_sheet_round_trips_the_share_and_refuses_one_out_of_range() -> None:
    assert_sheet_knob_field_round_trips("edge_level_share", 1, 0.85, 1.8)


def tension() -> TensionPlayParams:
    return TensionPlayParams(1.3, -2.0, 2.0, ANGLES, D_POS, D_NEG, (0.1,) * 3, (0.1,) * 3,
                             (-60.0,) * 3, (60.0,) * 3)


def sweeps_of(truth: TensionPlayParams) -> list[tuple[float, TrackedSweep]]:
    """One sweep per angle, the other knob held there."""
    return tracked_sweeps(truth, ANGLES)


def test_the_sheet_units_share_is_read_from_its_tip_against_its_edges() -> None:
    p = tension()
    truth = dataclasses.replace(p, level_grid=edge_level_grid(0.85, p.omega, ANGLES, D_POS,
                                                              D_NEG))
    fit = edge_share(sweeps_of(truth), p)
    assert fit is not None
    assert fit.share == pytest.approx(0.85, abs=0.05)
    assert fit.rms_after_deg < 0.3 < MIN_EDGE_LEVEL_GAIN_DEG < fit.rms_before_deg
    assert fit.keep


def test_a_tip_that_follows_its_edges_keeps_no_share() -> None:
    fit = edge_share(sweeps_of(tension()), tension())
    assert fit is not None
    assert fit.share == pytest.approx(0.0, abs=0.05)
    assert not fit.keep


def test_a_share_that_explains_too_little_is_not_kept() -> None:
    fit = fit_share([0.3, -0.2, 0.0, 0.1], [1.0, -1.0, 0.0, 2.0])
    assert fit.rms_before_deg - fit.rms_after_deg < MIN_EDGE_LEVEL_GAIN_DEG
    assert not fit.keep


def test_without_a_sweep_at_the_other_knobs_zero_there_is_no_share() -> None:
    assert edge_share([s for s in sweeps_of(tension()) if s[0] != 0.0], tension()) is None
