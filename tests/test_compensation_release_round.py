"""The rounded release (tsmd.compensation.release_round) in the tension play and method ours."""

from __future__ import annotations

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.play import assert_model_continuous_between_branches, assert_model_of_inverse_follows

from tsmd.compensation.ours_table import OursKnob
from tsmd.compensation.release_round import (
    REFERENCE_REVERSAL_DEG,
    reference_backlash_deg,
    rounded_drop_deg,
    rounded_gap_deg,
)
from tsmd.compensation.tension_play import Branches, PlayState, model_step, rest_state
from tsmd.compensation.tension_play_params import (
    BETA_RANGE,
    TensionPlayParams,
    tension_play_from_mapping,
    tension_play_to_mapping,
)


def params(beta_pos: float = 0.2, beta_neg: float = 0.22, x0_pos: float = -20.0,
           x0_neg: float = 15.0, release_round: float = 0.3, release_shift: float = 0.2,
           h_pos: float = -3.0, h_neg: float = 4.0, omega: float = 1.4) -> TensionPlayParams:
    grid = (-90.0, 90.0)
    return TensionPlayParams(omega, h_pos, h_neg, grid, (20.0, 20.0), (-22.0, -22.0),
                             (beta_pos,) * 2, (beta_neg,) * 2, (x0_pos,) * 2, (x0_neg,) * 2,
                             release_round=release_round, release_shift=release_shift)


def knob(p: TensionPlayParams) -> Branches:
    return OursKnob.from_params(p).at(0.0)


random_params = st.builds(
    params,
    beta_pos=st.floats(0.0, BETA_RANGE[1]),
    beta_neg=st.floats(0.0, BETA_RANGE[1]),
    x0_pos=st.floats(-60.0, 30.0),
    x0_neg=st.floats(-30.0, 60.0),
    release_round=st.floats(0.0, 1.0),
    release_shift=st.floats(-0.5, 1.0),
    h_pos=st.floats(-8.0, 8.0),
    h_neg=st.floats(-8.0, 8.0),
    omega=st.floats(0.5, 3.0),
)


def released_after(b: Branches, x_rev: float, travel_deg: float) -> float:
    """How far the output has fallen ``travel_deg`` back from a reversal at ``x_rev``."""
    state = model_step(rest_state(0.0, b), x_rev, b)
    return state.y_deg - model_step(state, x_rev - travel_deg, b).y_deg


@given(st.floats(-50.0, 50.0), st.floats(0.01, 20.0))
def test_rounded_gap_inverts_the_rounded_drop(gap_deg: float, k_deg: float) -> None:
    drop = rounded_drop_deg(gap_deg, k_deg)
    if drop > 0.0:
        assert rounded_gap_deg(drop, k_deg) == pytest.approx(gap_deg, abs=1e-6)


@given(st.floats(-50.0, 50.0), st.floats(0.01, 20.0))
def test_rounded_drop_is_never_before_the_sharp_corner(gap_deg: float, k_deg: float) -> None:
    assert rounded_drop_deg(gap_deg, k_deg) >= max(gap_deg, 0.0)
    assert rounded_drop_deg(gap_deg, k_deg) <= max(gap_deg, 0.0) + k_deg / 4.0 + 1e-12


def test_without_rounding_the_branches_are_the_sharp_models() -> None:
    sharp = OursKnob.from_params(params(release_round=0.0, release_shift=0.0)).at(0.0)
    plain = OursKnob.from_params(dataclasses.replace(
        params(), release_round=0.0, release_shift=0.0)).at(0.0)
    assert sharp == plain
    assert sharp.round_pos_deg == 0.0 and sharp.round_neg_deg == 0.0


def test_the_shift_moves_the_release_line_by_its_share_of_the_reference_backlash() -> None:
    p = params(release_round=0.0, release_shift=0.3)
    b_sharp = knob(dataclasses.replace(p, release_shift=0.0))
    b_shift = knob(p)
    b_ref = reference_backlash_deg(p.backlash_gain_pos[0], p.zero_load_pos_deg[0], 1)
    # the same fall happens 0.3 B_ref later in knob travel
    assert released_after(b_shift, 70.0, 30.0 + 0.3 * b_ref) == pytest.approx(
        released_after(b_sharp, 70.0, 30.0), abs=1e-4)


def test_the_rounded_release_leaves_the_hold_before_the_line_and_joins_it_later() -> None:
    p = params(release_round=0.4, release_shift=0.4)
    sharp = knob(dataclasses.replace(p, release_round=0.0))
    rounded = knob(p)
    backlash = p.backlash_gain_pos[0] * (70.0 - p.zero_load_pos_deg[0])
    b_ref = reference_backlash_deg(p.backlash_gain_pos[0], p.zero_load_pos_deg[0], 1)
    corner = backlash + 0.4 * b_ref
    assert released_after(rounded, 70.0, corner - 0.45 * b_ref) == 0.0
    assert released_after(rounded, 70.0, corner - 0.2 * b_ref) > 0.0
    assert released_after(sharp, 70.0, corner - 0.2 * b_ref) == 0.0
    far = corner + 0.5 * b_ref
    assert released_after(rounded, 70.0, far) == pytest.approx(released_after(sharp, 70.0, far),
                                                               abs=1e-6)


@given(random_params, st.lists(st.floats(-120.0, 120.0), min_size=2, max_size=60))
@settings(max_examples=150, deadline=None)
def test_rounded_output_is_continuous_and_between_the_branches(p: TensionPlayParams,
                                                              xs: list[float]) -> None:
    b = knob(p)
    steepest = p.omega / (1.0 - BETA_RANGE[1]) * (1.0 + 1e-6) + 1e-9
    assert_model_continuous_between_branches(b, xs, steepest)


@given(random_params, st.lists(st.floats(-100.0, 100.0), min_size=1, max_size=60))
@settings(max_examples=150, deadline=None)
def test_model_of_the_rounded_inverse_gives_the_desired_output(p: TensionPlayParams,
                                                              path: list[float]) -> None:
    b = knob(p)
    assert_model_of_inverse_follows(b, path)


def test_a_reversal_inside_the_dead_zone_keeps_the_output_on_its_hold() -> None:
    b = knob(params(release_round=1.0, release_shift=0.0))
    state = PlayState(0.0, b.rising(0.0), 1, b.rising(0.0))
    state = model_step(state, 5.0, b)
    back = model_step(state, 4.999, b)
    assert back.y_deg == pytest.approx(state.y_deg, abs=1e-9)


def test_the_profile_block_round_trips_the_rounded_release() -> None:
    p = params(release_round=0.25, release_shift=-0.1)
    again = tension_play_from_mapping(tension_play_to_mapping(p))
    assert (again.release_round, again.release_shift) == (0.25, -0.1)
    sharp = tension_play_to_mapping(params(release_round=0.0, release_shift=0.0))
    assert "release_round" not in sharp and "release_shift" not in sharp


def test_a_rounding_outside_its_range_is_refused_by_name() -> None:
    m = tension_play_to_mapping(params())
    m["release_round"] = 1.5
    with pytest.raises(ValueError, match="release_round"):
        tension_play_from_mapping(m)


def test_the_reference_backlash_is_the_one_at_a_90_deg_reversal() -> None:
    assert REFERENCE_REVERSAL_DEG == 90.0
    assert reference_backlash_deg(0.1, -10.0, 1) == pytest.approx(10.0)
    assert reference_backlash_deg(0.1, 10.0, -1) == pytest.approx(10.0)
