"""Our compensator (tsmd.compensation.ours): release lines, blend, coupling axis, fitting."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.profiles import make_profile

from tsmd.calibration.lag import estimate_lag_s
from tsmd.calibration.ours_fit import SweepData, fit_ours_knob
from tsmd.compensation import build_compensator, ours_compensator
from tsmd.compensation.ours import (
    OursState,
    envelopes,
    ours_inverse_step,
    ours_model_step,
    release_line,
    release_line_from_reference,
    smooth_max_excess,
    smooth_max_excess_inverse,
)
from tsmd.profile import DeviceKnob, KnobLimits, ReferencePoint

OMEGA = 1.3
D_POS, D_NEG, H_POS, H_NEG = 20.0, -20.0, -2.0, 2.0


def env(b_deg: float = 18.0, blend: float = 0.0):  # type: ignore[no-untyped-def]
    s_pos, p_pos = release_line(90.0, D_POS, b_deg, H_POS, H_NEG, OMEGA)
    s_neg, p_neg = release_line(-90.0, D_NEG, b_deg, H_NEG, H_POS, OMEGA)
    return envelopes(D_POS, D_NEG, H_POS, H_NEG, OMEGA, s_pos, s_neg, p_pos, p_neg, blend)


def backlash_after_reversal_at(x_rev: float, e) -> float:  # type: ignore[no-untyped-def]
    """Knob travel back from x_rev before the output drops by 1e-6."""
    state = OursState(x_rev, e.rising(x_rev), 1, e.rising(x_rev), 0.0)
    y0 = state.y_deg
    for x in np.arange(x_rev, x_rev - 80.0, -0.01):
        state = ours_model_step(state, float(x), e)
        if state.y_deg < y0 - 1e-6:
            return x_rev - float(x)
    return math.inf


def test_release_line_reproduces_the_backlash_at_the_calibration_amplitude() -> None:
    assert backlash_after_reversal_at(90.0, env(18.0)) == pytest.approx(18.0, abs=0.05)


def test_data_sheet_release_line_passes_the_reference_backlash_end_and_moves_with_d() -> None:
    slope, pivot = release_line_from_reference(72.0, 88.0, H_NEG, 1.6)
    assert H_NEG + slope * (72.0 - pivot) == pytest.approx(88.0)
    assert release_line_from_reference(72.0, 88.0, H_NEG, 1.6, 2.5)[1] == pytest.approx(
        pivot + 2.5)


def test_backlash_shrinks_with_the_load_at_the_reversal() -> None:
    e = env(18.0)
    widths = [backlash_after_reversal_at(x, e) for x in (40.0, 60.0, 90.0)]
    assert widths[0] < widths[1] < widths[2]


def test_release_slope_is_steeper_than_the_loaded_slope() -> None:
    assert release_line(90.0, D_POS, 18.0, H_POS, H_NEG, OMEGA)[0] > OMEGA


def test_release_slope_falls_back_to_omega_when_backlash_eats_the_travel() -> None:
    assert release_line(30.0, 20.0, 15.0, 0.0, 0.0, OMEGA) == (OMEGA, 20.0)


def test_smooth_max_inverse_inverts() -> None:
    for w in (0.0, 0.5, 3.0):
        for z in (0.01, 0.4, 2.0, 10.0):
            assert smooth_max_excess(smooth_max_excess_inverse(z, w), w) == pytest.approx(z)


def test_blend_keeps_the_output_continuous_at_the_reversal() -> None:
    e = env(18.0, blend=3.0)
    state = OursState(60.0, e.rising(60.0), 1, e.rising(60.0), 0.0)
    after = ours_model_step(state, 60.0 - 1e-6, e)
    assert after.y_deg == pytest.approx(state.y_deg, abs=1e-6)


def test_blend_rounds_the_backlash_corner() -> None:
    e = env(18.0, blend=4.0)
    state = OursState(90.0, e.rising(90.0), 1, e.rising(90.0), 0.0)
    xs = np.arange(90.0, 50.0, -0.05)
    ys = []
    for x in xs:
        state = ours_model_step(state, float(x), e)
        ys.append(state.y_deg)
    slope = np.diff(ys) / np.diff(xs)
    assert np.max(np.abs(np.diff(slope))) < 0.05  # no corner: the slope changes gradually


params = st.tuples(st.floats(8, 30), st.floats(-30, -8), st.floats(-4, 4), st.floats(-4, 4),
                   st.floats(0.9, 1.8), st.floats(0.9, 3.0), st.floats(0.9, 3.0),
                   st.floats(10, 40), st.floats(-40, -10), st.floats(0, 4))


@settings(max_examples=80, deadline=None)
@given(params, st.lists(st.floats(-30, 30), min_size=1, max_size=40))
def test_inverse_then_model_gives_the_desired_output(p: tuple[float, ...],
                                                      deltas: list[float]) -> None:
    e = envelopes(*p)
    y = np.clip(np.cumsum(deltas), -100, 100)
    state = OursState(0.0, e.rising(0.0), 1, e.rising(0.0), 0.0)
    model = state
    for target in y:
        state = ours_inverse_step(state, float(target), e)
        model = ours_model_step(model, state.x_deg, e)
        assert model.y_deg == pytest.approx(float(target), abs=1e-3)


def test_ours_follows_the_other_tips_loaded_knob_angle() -> None:
    profile = make_profile(d0=20.0)
    comp = build_compensator(profile, "ours", 0.004)
    comp.reset(np.array([0.0, 40.0]))
    knob = comp.knobs[1]  # type: ignore[attr-defined]
    axis = comp._axis  # type: ignore[attr-defined]
    assert axis[1] == pytest.approx(knob.loaded_knob_deg(40.0, axis[0]), abs=0.01)
    h_hi = max(knob.height_pos_deg, knob.height_neg_deg)
    assert axis[1] == pytest.approx(20.0 + (40.0 - h_hi) / knob.omega, abs=0.3)


def test_ours_leads_by_the_drive_lag() -> None:
    profile = make_profile()
    base = build_compensator(profile, "ours", 0.004)
    lag_knobs = tuple(
        type(k)(k.field, k.height_pos_deg, k.height_neg_deg, k.omega, 0.1)
        for k in base.knobs)  # type: ignore[attr-defined]
    lagged = type(base)(lag_knobs, 0.004)
    q = np.column_stack([np.linspace(30, 40, 200), np.zeros(200)])
    for c in (base, lagged):
        c.reset(q[0])
    out = [(base.command(r)[0], lagged.command(r)[0]) for r in q]
    v = 10.0 / (199 * 0.004)
    omega = base.knobs[0].omega  # type: ignore[attr-defined]  # the data sheet's loaded slope
    assert out[-1][1] - out[-1][0] == pytest.approx(0.1 * v / omega, rel=0.05)


def _sweep(d_pos: float, d_neg: float, b_pos: float, b_neg: float, other: float,
           delay_s: float = 0.0) -> SweepData:
    t = np.arange(0.0, 56.25, 0.004)
    cmd = 90.0 * np.sin(2 * np.pi * 0.04 * t)
    pos = np.interp(t - delay_s, t, cmd)
    return SweepData(t, cmd, pos, np.zeros_like(t), other, d_pos, d_neg, b_pos, b_neg)


DEVICE_KNOB = DeviceKnob(OMEGA, ReferencePoint(90.0, 90.0), ReferencePoint(-90.0, -90.0),
                         KnobLimits(-90, 90, 120, 2000))


def test_fit_gives_release_slopes_from_each_sweeps_amplitude_d_and_b() -> None:
    sweeps = [_sweep(20.0, -20.0, 18.0, 17.0, g) for g in (-90.0, 0.0, 90.0)]
    fit = fit_ours_knob(sweeps, DEVICE_KNOB)
    h_pos = 90.0 - OMEGA * 70.0
    h_neg = -90.0 + OMEGA * 70.0
    assert (fit.release_slope_pos[1], fit.release_pivot_pos_deg[1]) == pytest.approx(
        release_line(90.0, 20.0, 18.0, h_pos, h_neg, OMEGA), rel=1e-3)
    assert (fit.release_slope_neg[1], fit.release_pivot_neg_deg[1]) == pytest.approx(
        release_line(-90.0, -20.0, 17.0, h_neg, h_pos, OMEGA), rel=1e-3)
    assert len(fit.backlash_blend_deg) == 3


def test_fit_uses_the_data_sheet_release_slope() -> None:
    knob = dataclasses.replace(DEVICE_KNOB, release_omega=1.7, reference_backlash_pos_deg=18.0,
                               reference_backlash_neg_deg=17.0)
    sweeps = [_sweep(20.0, -21.0, 3.0, 3.0, 0.0), _sweep(23.0, -21.0, 3.0, 3.0, 60.0)]
    fit = fit_ours_knob(sweeps, knob)
    assert fit.release_slope_pos == (1.7, 1.7) and fit.release_slope_neg == (1.7, 1.7)
    h_neg = -90.0 + OMEGA * (90.0 - 21.0)
    assert fit.release_pivot_pos_deg[0] == pytest.approx(72.0 - (90.0 - h_neg) / 1.7)
    assert fit.release_pivot_pos_deg[1] - fit.release_pivot_pos_deg[0] == pytest.approx(3.0)


def test_fit_needs_a_sweep_for_every_grid_point() -> None:
    with pytest.raises(ValueError, match="no sweep with the other knob at 30"):
        fit_ours_knob([_sweep(20, -20, 18, 18, 0.0)], DEVICE_KNOB, (0.0, 30.0))


def test_fit_refuses_sweeps_without_identified_parameters() -> None:
    with pytest.raises(ValueError, match="no finite D/B"):
        fit_ours_knob([_sweep(math.nan, -20, 18, 18, 0.0)], DEVICE_KNOB)


def test_lag_estimate_recovers_a_known_delay() -> None:
    s = _sweep(20, -20, 18, 18, 0.0, delay_s=0.02)
    assert estimate_lag_s(s.t_s, s.cmd_deg, s.pos_deg) == pytest.approx(0.02, abs=0.002)


def test_dead_zone_crossing_is_centred_on_the_desired_crossing() -> None:
    profile = make_profile(d0=20.0)
    instant = ours_compensator(profile, 0.004, 1e6, 1e9)  # jumps in one tick, no look-ahead
    motor = ours_compensator(profile, 0.004, 120.0, 2000.0)
    t = np.arange(0.0, 4.0, 0.004)
    q = np.column_stack([-30.0 + 15.0 * t, np.zeros_like(t)])  # up through the dead zone
    cmds = {}
    for name, comp in (("instant", instant), ("motor", motor)):
        comp.reset(q[0])
        cmds[name] = np.array([comp.command(r)[0] for r in q])
        assert np.all(np.diff(cmds[name]) >= -1e-9), name  # never steps back: no false reversal
    jump = int(np.argmax(np.diff(cmds["instant"])))  # where the instant command crosses fastest
    middle = cmds["instant"][jump]
    mid_motor = int(np.argmax(cmds["motor"] > middle))
    assert abs(mid_motor - jump) * 0.004 < 0.1  # the motor is half-way when the jump is due
    assert cmds["motor"][jump - 30] > cmds["instant"][jump - 30] + 1.0  # and started early


def test_command_jerk_is_bounded_by_the_smoothing_window() -> None:
    profile = make_profile(d0=20.0)
    t = np.arange(0.0, 50.0, 0.004)
    q = np.column_stack([60 * np.sin(2 * np.pi * 0.04 * t), 60 * np.sin(2 * np.pi * 0.08 * t)])
    lim = KnobLimits(-90.0, 90.0, 120.0, 2000.0)
    cmds = {}
    for name in ("paper", "ours"):
        comp = build_compensator(profile, name, 0.004, [lim, lim])
        comp.reset(q[0])
        cmds[name] = np.array([comp.command(r) for r in q])
    v = np.diff(cmds["ours"], axis=0) / 0.004
    a = np.diff(v, axis=0) / 0.004
    jerk = {n: np.abs(np.diff(c, n=3, axis=0)).max() / 0.004**3 for n, c in cmds.items()}
    assert np.abs(v).max() <= 120.0 + 1e-6 and np.abs(a).max() <= 2000.0 + 1e-6
    assert jerk["ours"] <= 2 * 2000.0 / 0.1 * 1.05  # 2 a_max per 0.1 s window
    assert jerk["ours"] < jerk["paper"] / 10.0


def test_stopping_after_a_move_never_turns_the_command_back() -> None:
    profile = make_profile(d0=20.0)
    comp = build_compensator(profile, "ours", 0.004)
    s = 0.5 - 0.5 * np.cos(np.linspace(0.0, np.pi, 500))  # smooth move 0 -> -60, then rest
    q = np.concatenate([s * -60.0, np.full(500, -60.0)])
    rows = np.column_stack([np.zeros_like(q), q])
    comp.reset(rows[0])
    cmd = np.array([comp.command(r)[1] for r in rows])
    assert np.all(np.diff(cmd) <= 1e-9)  # monotone: no false reversal across the backlash
