"""The paper's piecewise-linear model L and its inverse F (tsmd.compensation.paper)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tsmd.compensation.paper import (
    Line,
    ModelState,
    PaperParams,
    falling_branch,
    height_from_reference,
    initial_state,
    inverse_step,
    model_step,
    rest_state,
    rising_branch,
)

# Hand-worked: D = +-20, B = 15, H = 0, omega = 1.3 -> D_hat_pos = -5, D_hat_neg = 5.
P = PaperParams(20.0, -20.0, 15.0, 15.0, 0.0, 0.0, 1.3)


def run(xs: list[float], p: PaperParams = P, start: ModelState | None = None
        ) -> list[tuple[float, Line]]:
    state = start or initial_state(xs[0], p, 1)
    out = []
    for x in xs:
        state, line = model_step(state, x, p)
        out.append((state.y_deg, line))
    return out


def test_d_hats_follow_equation_d_hats() -> None:
    p = PaperParams(22.0, -18.0, 14.0, 16.0, 1.0, -2.0, 1.32)
    assert p.d_hat_pos_deg == pytest.approx((1.0 + 2.0) / 1.32 - 18.0 + 16.0)
    assert p.d_hat_neg_deg == pytest.approx((-2.0 - 1.0) / 1.32 + 22.0 - 14.0)


def test_height_comes_from_reference_point_and_dead_zone_edge() -> None:
    assert height_from_reference(90.0, 91.0, 20.0, 1.3) == pytest.approx(0.0)
    assert height_from_reference(-90.0, -95.0, -20.0, 1.3) == pytest.approx(-4.0)


def test_rising_sweep_follows_l2_l3_l4() -> None:
    start = initial_state(-90.0, P, 1)
    out = run([-60.0, -10.0, 0.0, 10.0, 30.0, 60.0], start=start)
    assert [line for _, line in out] == [Line.L2, Line.L2, Line.L3, Line.L3, Line.L4, Line.L4]
    assert out[0][0] == pytest.approx(1.3 * (-60 + 5))
    assert out[4][0] == pytest.approx(1.3 * (30 - 20))


def test_falling_sweep_follows_l6_l7_l8() -> None:
    start = initial_state(90.0, P, -1)
    out = run([60.0, 10.0, 0.0, -10.0, -30.0], start=start)
    assert [line for _, line in out] == [Line.L6, Line.L6, Line.L7, Line.L7, Line.L8]
    assert out[0][0] == pytest.approx(1.3 * (60 - 5))
    assert out[4][0] == pytest.approx(1.3 * (-30 + 20))


def test_reversal_at_top_holds_output_on_l5_for_the_backlash_width() -> None:
    start = initial_state(60.0, P, 1)  # on L4 at 1.3*40 = 52
    out = run([60.0, 55.0, 46.0, 45.0, 40.0], start=start)
    assert [line for _, line in out][1:3] == [Line.L5, Line.L5]
    assert out[2][0] == pytest.approx(52.0)
    assert out[4][0] == pytest.approx(1.3 * (40 - 5))  # back on L6 after B = 15
    assert out[4][1] == Line.L6


def test_reversal_at_bottom_holds_output_on_l1() -> None:
    start = initial_state(-60.0, P, -1)  # on L8 at -52
    out = run([-60.0, -50.0, -46.0, -40.0], start=start)
    assert [line for _, line in out][1:3] == [Line.L1, Line.L1]
    assert out[1][0] == pytest.approx(-52.0)
    assert out[3][0] == pytest.approx(1.3 * (-40 + 5))


def test_reversal_updates_the_reference_point() -> None:
    state = initial_state(50.0, P, 1)
    state, _ = model_step(state, 60.0, P)
    state, _ = model_step(state, 58.0, P)
    assert state.reference_deg == (60.0, pytest.approx(52.0))
    assert state.direction == -1


def test_standing_still_keeps_direction_and_output() -> None:
    state = initial_state(60.0, P, 1)
    state, _ = model_step(state, 55.0, P)
    again, line = model_step(state, 55.0, P)
    assert again.direction == -1 and again.y_deg == state.y_deg and line == Line.L5


def test_reversal_inside_dead_zone_holds_dead_zone_height() -> None:
    state = initial_state(-90.0, P, 1)
    out = run([0.0, 10.0, 8.0, 6.0], start=state)
    assert [line for _, line in out] == [Line.L3, Line.L3, Line.L5, Line.L5]
    assert all(y == pytest.approx(0.0) for y, _ in out)


def test_reversal_inside_backlash_keeps_the_held_output() -> None:
    state = initial_state(60.0, P, 1)
    out = run([60.0, 52.0, 56.0, 60.0, 61.0], start=state)
    assert [line for _, line in out][1:3] == [Line.L5, Line.L1]
    assert out[3][0] == pytest.approx(52.0)
    assert out[4][0] == pytest.approx(1.3 * 41)


def test_large_step_lands_on_the_branch_of_its_direction() -> None:
    state = initial_state(-90.0, P, -1)
    state, line = model_step(state, 90.0, P)
    assert line == Line.L4 and state.y_deg == pytest.approx(1.3 * 70)


def test_inverse_crosses_dead_zone_with_a_jump() -> None:
    state = rest_state(-1.0, P)
    state = inverse_step(state, 1.0, P)
    assert state.x_deg == pytest.approx(20.0 + 1.0 / 1.3)


def test_inverse_jumps_the_backlash_at_reversal() -> None:
    state = initial_state(60.0, P, 1)
    state = inverse_step(state, 51.0, P)
    assert state.x_deg == pytest.approx(5.0 + 51.0 / 1.3)


def test_inverse_holds_command_when_desired_output_stands_still() -> None:
    state = initial_state(60.0, P, 1)
    assert inverse_step(state, state.y_deg, P) == state


def test_rest_state_at_home_sits_in_the_dead_zone() -> None:
    assert rest_state(0.0, P).x_deg == 0.0
    assert rest_state(40.0, P).x_deg == pytest.approx(20 + 40 / 1.3)
    assert rest_state(-40.0, P).x_deg == pytest.approx(-20 - 40 / 1.3)


params = st.builds(
    PaperParams,
    st.floats(5, 35), st.floats(-35, -5), st.floats(0, 30), st.floats(0, 30),
    st.floats(-5, 5), st.floats(-5, 5), st.floats(0.8, 2.0))
steps = st.lists(st.floats(-40, 40), min_size=1, max_size=60)


@settings(max_examples=150, deadline=None)
@given(params, steps)
def test_inverse_then_model_gives_the_desired_output(p: PaperParams, deltas: list[float]) -> None:
    y = np.clip(np.cumsum(deltas), -110, 110)
    state = rest_state(0.0, p)
    model = state
    for target in y:
        state = inverse_step(state, float(target), p)
        model, _ = model_step(model, state.x_deg, p)
        assert model.y_deg == pytest.approx(float(target), abs=1e-9)


@settings(max_examples=150, deadline=None)
@given(params, steps)
def test_inverse_recovers_input_outside_flat_parts(p: PaperParams, deltas: list[float]) -> None:
    xs = np.clip(np.cumsum(deltas), -100, 100)
    model = initial_state(0.0, p, 1)
    inv = model
    for x in xs:
        model, line = model_step(model, float(x), p)
        inv = inverse_step(inv, model.y_deg, p)
        if line in (Line.L2, Line.L4, Line.L6, Line.L8) and model.y_deg != inv.y_deg:
            pytest.fail("inverse lost the output")
        if line in (Line.L2, Line.L4, Line.L6, Line.L8):
            assert inv.x_deg == pytest.approx(float(x), abs=1e-7)


@settings(max_examples=100, deadline=None)
@given(params, st.floats(-100, 100), st.floats(-100, 100))
def test_model_output_is_continuous_in_the_input(p: PaperParams, x0: float, x1: float) -> None:
    state = initial_state(x0, p, 1)
    a, _ = model_step(state, x1, p)
    b, _ = model_step(state, x1 + 1e-6, p)
    assert abs(a.y_deg - b.y_deg) <= p.omega * 1e-6 + 1e-9


@settings(max_examples=100, deadline=None)
@given(params, steps)
def test_rising_branch_never_above_falling_branch(p: PaperParams, deltas: list[float]) -> None:
    for x in np.clip(np.cumsum(deltas), -100, 100):
        assert rising_branch(float(x), p)[0] <= falling_branch(float(x), p)[0]


def test_rejects_non_positive_omega() -> None:
    with pytest.raises(ValueError, match="omega"):
        PaperParams(20, -20, 10, 10, 0, 0, 0.0)
    with pytest.raises(ValueError, match="omega"):
        PaperParams(20, -20, 10, 10, 0, 0, math.nan)
