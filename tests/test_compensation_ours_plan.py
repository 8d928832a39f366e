"""Ours with a plan (the loop playing a trajectory): the dead-zone crossing timed on the plan."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_compensation_ours import (
    LIMITS,
    PERIOD_S,
    assert_within_limits,
    compensator,
    knob_branches,
    params,
    random_params,
    samples,
)

from tsmd.compensation.ours import OursCompensator
from tsmd.compensation.tension_play import PlayState, model_step, widest_flat


def run_planned(comp: OursCompensator, q: np.ndarray, plan: np.ndarray | None = None
                ) -> np.ndarray:
    """Commands for ``q`` with ``plan`` (default: ``q`` itself) previewed every tick."""
    rows = (q if plan is None else plan).tolist()
    comp.reset(q[0] if np.all(np.isfinite(q[0])) else np.zeros(2))
    out = []
    for i, row in enumerate(q):
        comp.preview(rows, i)
        out.append(comp.command(row, PERIOD_S))
    return np.array(out)


def tip_of(cmd: np.ndarray, y0: float) -> np.ndarray:
    """The forward model as the catheter (knob 1)."""
    b = knob_branches(params())
    state = PlayState(cmd[0, 0], y0, -1, y0)
    tip = []
    for x in cmd[:, 0]:
        state = model_step(state, x, b)
        tip.append(state.y_deg)
    return np.array(tip)


def move_across_the_dead_zone() -> np.ndarray:
    """1 s at rest at -20 deg, then a 1.5 s raised-cosine move to +60 deg, then rest (knob 1)."""
    t = np.arange(1500) * PERIOD_S
    q = np.full((t.size, 2), -20.0)
    s = np.clip((t - 1.0) / 1.5, 0.0, 1.0)
    q[:, 0] = -20.0 + 80.0 * (0.5 - 0.5 * np.cos(math.pi * s))
    return q


def test_each_branch_has_its_dead_zone_as_widest_flat() -> None:
    p = params()
    b = knob_branches(p)
    assert b.rising_flat is not None and b.falling_flat is not None
    assert b.rising_flat.hi_deg == pytest.approx(p.dead_zone_pos_deg[0])
    assert b.rising_flat.y_deg == pytest.approx(p.height_pos_deg, abs=1e-3)
    assert b.falling_flat.lo_deg == pytest.approx(p.dead_zone_neg_deg[0])
    assert b.falling_flat.y_deg == pytest.approx(p.height_neg_deg, abs=1e-3)


def test_a_branch_without_a_flat_part_has_no_widest_flat() -> None:
    assert widest_flat((-10.0, 0.0, 10.0), (-20.0, 0.0, 30.0), omega=1.5) is None


def test_a_planned_crossing_leaves_equal_errors_at_the_plateau_entry_and_exit() -> None:
    q = move_across_the_dead_zone()
    cmd = run_planned(compensator(), q)
    e = (tip_of(cmd, -20.0) - q[:, 0])[250:]
    assert e.max() > 0.0 > e.min()
    assert abs(e.max() + e.min()) <= 0.1 * (e.max() - e.min())


def test_a_planned_crossing_has_a_smaller_peak_error_than_a_causal_one() -> None:
    q = move_across_the_dead_zone()
    planned = tip_of(run_planned(compensator(), q), -20.0) - q[:, 0]
    comp = compensator()
    comp.reset(q[0])
    causal = tip_of(np.array([comp.command(row, PERIOD_S) for row in q]), -20.0) - q[:, 0]
    assert np.ptp(planned[250:]) < np.ptp(causal[250:])


def test_a_plan_without_a_turn_or_a_dead_zone_ahead_changes_no_command() -> None:
    t = np.arange(2000) * PERIOD_S
    q = np.column_stack([30.0 + 6.0 * t] * 2)  # up the loaded side only
    comp = compensator()
    comp.reset(q[0])
    causal = np.array([comp.command(row, PERIOD_S) for row in q])
    assert np.array_equal(run_planned(compensator(), q), causal)


def test_a_plan_is_used_only_in_the_tick_it_was_given() -> None:
    q = move_across_the_dead_zone()
    comp = compensator()
    run_planned(comp, q[:400])
    comp.command(q[400], PERIOD_S)
    assert comp._planner.fresh is False


@given(random_params, st.lists(st.tuples(samples, samples, samples, samples), min_size=1,
                               max_size=120))
@settings(max_examples=100, deadline=None)
def test_planned_commands_respect_every_limit_for_any_plan_and_input(
        p: object, rows: list[tuple[float, float, float, float]]) -> None:
    """The plan may disagree with the desired angles (or hold NaN, inf, +-500 deg): the
    command stays finite and within every limit."""
    a = np.array(rows, dtype=float)
    comp = compensator(p)  # type: ignore[arg-type]
    assert_within_limits(run_planned(comp, a[:, :2], a[:, 2:]))
    assert LIMITS.max_velocity_deg_s == comp.v_max


def triangle() -> np.ndarray:
    """Knob 1: 0.1 Hz triangle of +-60 deg (24 deg/s, turns at once); knob 2 at rest."""
    t = np.arange(5000) * PERIOD_S
    phase = (0.1 * t) % 1.0
    tri = 60.0 * np.where(phase < 0.25, 4 * phase, np.where(phase < 0.75, 2 - 4 * phase,
                                                            4 * phase - 4))
    return np.column_stack([tri, np.zeros_like(tri)])


def test_a_planned_turn_lowers_the_peak_error_around_a_sharp_turn() -> None:
    q = triangle()
    window = slice(500, 800)  # around the turn at +60 deg (t = 2.5 s)
    planned = tip_of(run_planned(compensator(), q), 0.0) - q[:, 0]
    comp = compensator()
    comp.reset(q[0])
    causal = tip_of(np.array([comp.command(row, PERIOD_S) for row in q]), 0.0) - q[:, 0]
    assert np.abs(planned[window]).max() < 0.5 * np.abs(causal[window]).max()


def test_a_held_crossing_ends_when_the_plan_turns_again() -> None:
    """A zigzag faster than the crossings: whatever the plan did, once it stands the knob is
    where the model's inverse puts it (no hold left over)."""
    t = np.arange(1500) * PERIOD_S
    zig = 40.0 * np.sign(np.sin(2 * math.pi * 3.0 * t)) * np.minimum(t, 1.0)
    q = np.column_stack([zig, np.zeros_like(zig)])
    q[1000:, 0] = q[999, 0]
    comp = compensator()
    cmd = run_planned(comp, q)
    assert comp._k[0].plan.direction == 0
    assert cmd[-1, 0] == pytest.approx(comp._k[0].state.x_deg, abs=1e-6)
