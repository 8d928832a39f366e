"""Compensators for two knobs, the parameter grids and the output limiter."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.profiles import ROOT, make_profile

from tsmd.compensation import (
    CompensationError,
    Compensator,
    KnobLimits,
    NoCompensation,
    build_compensator,
)
from tsmd.compensation.grid import ParameterField
from tsmd.compensation.ours_table import OursKnob
from tsmd.compensation.paper import at_other_knob_zero, offset_edges, plateau_heights
from tsmd.compensation.safety import LimiterState, limit_step
from tsmd.profile import load_profile

LIMITS = KnobLimits(-100.0, 100.0, 180.0, 2000.0)
DT = 0.004


def sine(n: int = 2500, amp: float = 60.0) -> np.ndarray:
    t = np.arange(n) * DT
    return np.column_stack([amp * np.sin(2 * np.pi * 0.4 * t), 30 * np.sin(2 * np.pi * 0.8 * t)])


def run(comp: Compensator, q: np.ndarray) -> np.ndarray:
    comp.reset(q[0])
    return np.array([comp.command(row, DT) for row in q])


@pytest.mark.parametrize("method", ["none", "paper", "ours"])
def test_every_method_is_a_compensator(method: str) -> None:
    comp = build_compensator(make_profile(), method, DT)
    assert isinstance(comp, Compensator)
    assert run(comp, sine(50)).shape == (50, 2)


def test_no_compensation_passes_desired_angles_through() -> None:
    q = sine(100)
    assert np.array_equal(run(NoCompensation(), q), q)


def test_non_finite_setpoint_holds_the_last_command() -> None:
    for method in ("none", "paper"):
        comp = build_compensator(make_profile(), method, DT)
        comp.reset(np.zeros(2))
        a = comp.command(np.array([10.0, 5.0]), DT)
        b = comp.command(np.array([math.nan, math.inf]), DT)
        assert np.array_equal(a, b), method


def test_non_finite_setpoint_keeps_ours_going_where_the_last_finite_one_led() -> None:
    """Ours' command is rate limited: it may not stop dead, it keeps its target."""
    held, repeated = (build_compensator(make_profile(), "ours", DT) for _ in range(2))
    for comp in (held, repeated):
        comp.reset(np.zeros(2))
        comp.command(np.array([10.0, 5.0]), DT)
    for _ in range(200):
        a = held.command(np.array([math.nan, math.inf]), DT)
        b = repeated.command(np.array([10.0, 5.0]), DT)
        assert np.array_equal(a, b)


def test_unknown_method_and_missing_profile_are_refused() -> None:
    with pytest.raises(CompensationError, match="'magic' is not one of"):
        build_compensator(make_profile(), "magic", DT)
    with pytest.raises(CompensationError, match="needs a catheter profile"):
        build_compensator(None, "paper", DT)


def test_ours_without_its_parameters_is_refused_with_advice() -> None:
    profile = make_profile()
    knob = profile.knobs[0]
    object.__setattr__(knob, "tension_play", None)
    with pytest.raises(CompensationError, match="no parameters for method 'ours'.*recalibrate"):
        build_compensator(profile, "ours", DT)


def test_paper_compensation_adds_the_dead_zone_when_moving_out() -> None:
    comp = build_compensator(make_profile(d0=20.0), "paper", DT)
    comp.reset(np.zeros(2))
    cmd = comp.command(np.array([13.0, 0.0]), DT)
    knob = make_profile().knobs[0]
    assert cmd[0] == pytest.approx(20.0 + (13.0 - knob.height_pos_deg) / knob.omega)


def test_paper_parameters_follow_the_other_knob() -> None:
    comp = build_compensator(make_profile(d0=20.0), "paper", DT)
    comp.reset(np.array([0.0, 90.0]))
    cmd = comp.command(np.array([13.0, 90.0]), DT)
    knob = make_profile().knobs[0]
    assert cmd[0] == pytest.approx(17.0 + (13.0 - knob.height_pos_deg) / knob.omega)


def test_limited_output_never_leaves_knob_limits() -> None:
    comp = build_compensator(make_profile(), "paper", DT, [LIMITS, LIMITS])
    q = sine(2000, amp=150.0)
    out = run(comp, q)
    assert out.min() >= LIMITS.min_deg and out.max() <= LIMITS.max_deg


def test_limited_output_respects_velocity_and_acceleration() -> None:
    comp = build_compensator(make_profile(), "paper", DT, [LIMITS, LIMITS])
    out = run(comp, sine(2500))
    v = np.diff(out, axis=0) / DT
    assert np.abs(v).max() <= LIMITS.max_velocity_deg_s + 1e-6
    assert np.abs(np.diff(v, axis=0)).max() <= LIMITS.max_accel_deg_s2 * DT + 1e-6


targets = st.lists(st.one_of(st.floats(-500, 500), st.sampled_from([math.nan, math.inf])),
                   min_size=1, max_size=80)


@settings(max_examples=200, deadline=None)
@given(targets, st.floats(-100, 100), st.floats(-180, 180))
def test_limiter_respects_every_limit_for_any_targets(
        seq: list[float], q0: float, v0: float) -> None:
    state = LimiterState(q0, v0)
    for target in seq:
        nxt = limit_step(state, target, LIMITS, DT)
        assert LIMITS.min_deg <= nxt.q_deg <= LIMITS.max_deg
        assert abs(nxt.v_deg_s) <= LIMITS.max_velocity_deg_s + 1e-9
        hits_bound = nxt.q_deg in (LIMITS.min_deg, LIMITS.max_deg)
        if not hits_bound:
            assert abs(nxt.v_deg_s - state.v_deg_s) <= LIMITS.max_accel_deg_s2 * DT + 1e-9
        state = nxt


def test_limiter_settles_on_a_reachable_target_without_real_overshoot() -> None:
    state = LimiterState(0.0)
    trace = []
    for _ in range(500):
        state = limit_step(state, 40.0, LIMITS, DT)
        trace.append(state.q_deg)
    assert max(trace) <= 40.0 + 0.01 and trace[-1] == pytest.approx(40.0)


def test_parameter_field_holds_end_values_outside_the_grid() -> None:
    f = ParameterField([-90, 0, 90], np.array([[1.0], [3.0], [2.0]]), "pchip")
    assert f.at(-120)[0] == 1.0 and f.at(200)[0] == 2.0


@pytest.mark.parametrize("method", ["pchip", "linear", "cubic"])
def test_parameter_field_passes_through_grid_points(method: str) -> None:
    grid = [-90, -60, -30, 0, 30, 60, 90]
    vals = np.array([[14.0 + abs(g) / 10, -14.0 - abs(g) / 10] for g in grid])
    f = ParameterField(grid, vals, method)
    for g, v in zip(grid, vals, strict=True):
        assert np.allclose(f.at(g), v)


def test_pchip_does_not_overshoot_between_grid_points() -> None:
    grid = [-90, -60, -30, 0, 30, 60, 90]
    vals = np.array([[10.0], [10.0], [10.0], [20.0], [20.0], [20.0], [20.0]])
    f = ParameterField(grid, vals, "pchip")
    xs = np.linspace(-90, 90, 361)
    ys = np.array([f.at(x)[0] for x in xs])
    assert ys.min() >= 10.0 - 1e-12 and ys.max() <= 20.0 + 1e-12


def test_named_parameter_field_finds_its_columns_by_name() -> None:
    f = ParameterField.from_columns([-90, 0, 90], {"dead_zone_pos_deg": [14, 15, 16],
                                                   "backlash_pos_deg": [20, 21, 22]}, "linear")
    assert f.columns == ("dead_zone_pos_deg", "backlash_pos_deg")
    assert f.at(0)[f.column("backlash_pos_deg")] == 21.0
    with pytest.raises(KeyError, match="no parameter 'omega'"):
        f.column("omega")


def test_shifting_a_named_parameter_moves_only_that_parameter() -> None:
    f = ParameterField.from_columns([-90, 0, 90], {"a": [1, 2, 3], "b": [4, 5, 6]}, "linear")
    g = f.shifted({"b": -1.5})
    assert np.array_equal(g.values[:, 0], f.values[:, 0])
    assert np.array_equal(g.values[:, 1], f.values[:, 1] - 1.5)
    assert g.columns == f.columns


def test_a_field_refuses_column_names_that_do_not_match_its_values() -> None:
    with pytest.raises(ValueError, match="2 column names for 1 columns"):
        ParameterField([-90, 0, 90], np.array([[1.0], [2.0], [3.0]]), "linear", ("a", "b"))


def test_our_knob_refuses_a_field_without_its_named_columns() -> None:
    unnamed = ParameterField([-90, 0, 90], np.zeros((3, 7)), "linear")
    with pytest.raises(ValueError, match="must hold"):
        OursKnob(unnamed, 1.5, 5.0, -5.0, 0.0)


def test_plateau_heights_come_from_the_reference_line_through_the_edge_at_zero() -> None:
    profile = load_profile(ROOT / "profiles" / "example-sim.yaml")
    k = profile.knobs[0]
    d_pos0 = at_other_knob_zero(k.other_knob_deg, k.dead_zone_pos_deg)
    d_neg0 = at_other_knob_zero(k.other_knob_deg, k.dead_zone_neg_deg)
    h_pos, h_neg = plateau_heights(k, d_pos0, d_neg0)
    assert h_pos == pytest.approx(k.reference_pos.tip_deg
                                  - k.omega * (k.reference_pos.knob_deg - d_pos0))
    assert h_neg == pytest.approx(k.reference_neg.tip_deg
                                  - k.omega * (k.reference_neg.knob_deg - d_neg0))


def test_the_dead_zone_offset_moves_both_edges_outward() -> None:
    d_pos, d_neg = offset_edges([15.0, 16.0], [-14.0, -15.0], 0.5)
    assert d_pos.tolist() == [15.5, 16.5] and d_neg.tolist() == [-14.5, -15.5]


def test_example_profile_builds_every_method() -> None:
    profile = load_profile(ROOT / "profiles" / "example-sim.yaml")
    for method in ("none", "paper", "ours"):
        build_compensator(profile, method, DT, [LIMITS, LIMITS])


def test_limits_given_without_apply_limits_are_not_applied_by_the_compensator() -> None:
    """The loop applies the limiter itself; the compensator must not limit a second time."""
    profile = load_profile(ROOT / "profiles" / "example-sim.yaml")
    jump = np.array([80.0, 0.0])
    for method in ("none", "paper"):
        free = build_compensator(profile, method, DT, [LIMITS, LIMITS], apply_limits=False)
        limited = build_compensator(profile, method, DT, [LIMITS, LIMITS])
        free.reset(np.zeros(2))
        limited.reset(np.zeros(2))
        step_free = abs(free.command(jump, DT)[0])
        step_limited = abs(limited.command(jump, DT)[0])
        assert step_limited <= LIMITS.max_velocity_deg_s * DT + 1e-9
        assert step_free > step_limited


def test_limiter_follows_a_feasible_moving_target_without_lag() -> None:
    t = np.arange(0.0, 5.0, DT)
    target = 50.0 * (1.0 - np.cos(2 * np.pi * 0.2 * t))  # from rest; 63 deg/s, 79 deg/s^2
    state = LimiterState(float(target[0]), 0.0, float(target[0]))
    out = []
    for x in target:
        state = limit_step(state, float(x), LIMITS, DT)
        out.append(state.q_deg)
    assert np.max(np.abs(np.array(out) - target)) < 1e-9
