"""The product's loaded level over the other knob's angle (tsmd.compensation.level_grid) in
method ours' table rows, the profile and the data sheet."""

from __future__ import annotations

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.play import assert_model_continuous_between_branches, assert_model_of_inverse_follows
from test_compensation_tension_play_fit import DEVICE_KNOB, synthetic_sweep

from tsmd.calibration.tension_play_fit import fit_tension_play
from tsmd.compensation.level_grid import LevelGrid, level_grid_from_mapping, level_grid_to_mapping
from tsmd.compensation.ours_table import OursKnob
from tsmd.compensation.safety import KnobLimits
from tsmd.compensation.tension_play_params import (
    BETA_RANGE,
    TensionPlayParams,
    tension_play_from_mapping,
    tension_play_to_mapping,
)
from tsmd.profile.device import DeviceKnob, DeviceModel, ReferencePoint
from tsmd.profile.sheet_schema import device_model_from_mapping, device_model_to_mapping

GRID = LevelGrid((-90.0, 0.0, 60.0, 90.0), (-3.0, 0.0, -2.0, -4.0), (4.0, 0.0, 2.0, 3.0))


def params(level: LevelGrid | None = GRID, release_round: float = 0.0,
           h_pos: float = -3.0, h_neg: float = 4.0, omega: float = 1.4,
           beta: float = 0.2) -> TensionPlayParams:
    grid = (-90.0, 90.0)
    return TensionPlayParams(omega, h_pos, h_neg, grid, (20.0, 20.0), (-22.0, -22.0),
                             (beta,) * 2, (beta,) * 2, (-20.0,) * 2, (15.0,) * 2,
                             release_round=release_round, level_grid=level)


def test_the_grid_is_linear_between_its_angles_and_held_beyond() -> None:
    assert GRID.at(30.0) == pytest.approx((-1.0, 1.0))
    assert GRID.at(75.0) == pytest.approx((-3.0, 2.5))
    assert GRID.at(120.0) == pytest.approx((-4.0, 3.0))
    assert GRID.at(-120.0) == pytest.approx((-3.0, 4.0))


def test_without_a_grid_and_with_a_zero_grid_the_branches_are_the_same() -> None:
    zero = LevelGrid((-90.0, 90.0), (0.0, 0.0), (0.0, 0.0))
    for other in (-90.0, 0.0, 45.0, 90.0):
        a = OursKnob.from_params(params(level=None)).at(other)
        b = OursKnob.from_params(params(level=zero)).at(other)
        assert (a.knots, a.rising_deg, a.falling_deg) == (b.knots, b.rising_deg, b.falling_deg)


@pytest.mark.parametrize("other", [-90.0, 0.0, 30.0, 60.0, 75.0])
def test_each_side_loaded_branch_moves_by_its_shift_at_the_other_knobs_angle(
        other: float) -> None:
    plain = OursKnob.from_params(params(level=None)).at(other)
    moved = OursKnob.from_params(params()).at(other)
    shift_pos, shift_neg = GRID.at(other)
    # far on each loaded side, where the branch is the loaded line alone
    assert moved.rising(70.0) - plain.rising(70.0) == pytest.approx(shift_pos, abs=1e-9)
    assert moved.falling(-70.0) - plain.falling(-70.0) == pytest.approx(shift_neg, abs=1e-9)


random_params = st.builds(
    params,
    level=st.builds(
        LevelGrid, st.just((-90.0, 0.0, 90.0)),
        st.tuples(st.floats(-6.0, 6.0), st.just(0.0), st.floats(-6.0, 6.0)),
        st.tuples(st.floats(-6.0, 6.0), st.just(0.0), st.floats(-6.0, 6.0))),
    release_round=st.floats(0.0, 1.0),
    h_pos=st.floats(-8.0, 8.0),
    h_neg=st.floats(-8.0, 8.0),
    omega=st.floats(0.5, 3.0),
    beta=st.floats(0.0, BETA_RANGE[1]),
)


@given(random_params, st.floats(-90.0, 90.0),
       st.lists(st.floats(-120.0, 120.0), min_size=2, max_size=60))
@settings(max_examples=150, deadline=None)
def test_a_shifted_row_stays_continuous_and_between_its_branches(
        p: TensionPlayParams, other: float, xs: list[float]) -> None:
    b = OursKnob.from_params(p).at(other)
    steepest = p.omega / (1.0 - BETA_RANGE[1]) * (1.0 + 1e-6) + 1e-9
    assert_model_continuous_between_branches(b, xs, steepest)


@given(random_params, st.floats(-90.0, 90.0),
       st.lists(st.floats(-100.0, 100.0), min_size=1, max_size=60))
@settings(max_examples=150, deadline=None)
def test_the_model_of_a_shifted_rows_inverse_gives_the_desired_output(
        p: TensionPlayParams, other: float, path: list[float]) -> None:
    b = OursKnob.from_params(p).at(other)
    assert_model_of_inverse_follows(b, path)


def test_the_profile_block_round_trips_the_level_grid() -> None:
    again = tension_play_from_mapping(tension_play_to_mapping(params()))
    assert again.level_grid == GRID
    assert "loaded_level_grid" not in tension_play_to_mapping(params(level=None))


@pytest.mark.parametrize(("key", "value", "message"), [
    ("other_knob_deg", [0.0, 0.0, 60.0, 90.0], "increasing"),
    ("pos_deg", [0.0, 1.0], "one per angle"),
    ("neg_deg", [0.0, 0.0, 40.0, 0.0], r"neg_deg\[2\]"),
    ("colour", "red", "unknown key"),
])
def test_a_bad_level_grid_is_refused_by_name(key: str, value: object, message: str) -> None:
    m: dict[str, object] = dict(level_grid_to_mapping(GRID))
    m[key] = value
    with pytest.raises(ValueError, match=message):
        level_grid_from_mapping(m, "loaded_level_grid")


def test_the_data_sheet_round_trips_the_level_grid() -> None:
    knob = DeviceKnob(1.3, ReferencePoint(90.0, 70.0), ReferencePoint(-90.0, -72.0),
                      KnobLimits(-90.0, 90.0, 120.0, 2000.0), loaded_level_grid=GRID)
    sheet = DeviceModel("family-test", (knob, dataclasses.replace(knob, loaded_level_grid=None)))
    again = device_model_from_mapping(device_model_to_mapping(sheet))
    assert again.knobs[0].loaded_level_grid == GRID
    assert again.knobs[1].loaded_level_grid is None


def test_calibration_copies_the_sheets_level_grid_into_the_profile() -> None:
    sweeps = [synthetic_sweep(g) for g in (-90.0, 0.0, 90.0)]
    plain = fit_tension_play(sweeps, DEVICE_KNOB)
    with_grid = fit_tension_play(sweeps, dataclasses.replace(DEVICE_KNOB, loaded_level_grid=GRID))
    assert plain.level_grid is None
    assert with_grid == dataclasses.replace(plain, level_grid=GRID)
