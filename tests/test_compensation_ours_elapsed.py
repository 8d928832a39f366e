"""Ours counts time in seconds, not ticks: a late tick (the loop measured its elapsed time)
changes neither the command's limits nor its smoothing nor its velocity estimate in time."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_compensation_ours import LIMITS, PERIOD_S, params, random_params, samples

from tsmd.compensation.ours import OursCompensator
from tsmd.compensation.ours_knob import KnobCommand, motion
from tsmd.compensation.ours_table import ours_knobs
from tsmd.compensation.safety import MAX_TICK_PERIODS, KnobLimiter, KnobLimits, tick_time_s
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.config import default_sim_config
from tsmd.profile import load_profile
from tsmd.stack import make_compensator


def commands_at_times(q_of_t: object, late_every: int, duration_s: float,
                      limits: KnobLimits = LIMITS) -> tuple[np.ndarray, np.ndarray]:
    """Ours driven on ``q_of_t`` (a function of time, knob 1; knob 2 at 0) for ``duration_s``;
    every ``late_every``-th tick comes three periods after the last (0: none late). Returns the
    tick times and knob 1's commands."""
    comp = OursCompensator(ours_knobs((params(), params())), PERIOD_S, (limits, limits))
    comp.reset(np.array([q_of_t(0.0), 0.0]))  # type: ignore[operator]
    t_s, k, times, out = 0.0, 0, [], []
    while t_s < duration_s:
        k += 1
        dt = 3 * PERIOD_S if late_every and k % late_every == 0 else PERIOD_S
        t_s += dt
        times.append(t_s)
        out.append(comp.command(np.array([q_of_t(t_s), 0.0]), dt)[0])  # type: ignore[operator]
    return np.array(times), np.array(out)


def test_a_late_tick_moves_the_command_as_far_as_the_time_it_covers() -> None:
    # a step from home far beyond the flat: the command runs at the velocity limit; a late
    # tick moves it by at most the limit over its time, and (the target taken as reached
    # evenly over the periods missed) by at most the two missed periods' travel ahead
    t_on, on = commands_at_times(lambda t: 0.0 if t < 0.02 else 60.0, 0, 0.4)
    t_late, late = commands_at_times(lambda t: 0.0 if t < 0.02 else 60.0, 3, 0.4)
    assert late[-1] - late[0] > 30.0
    speed = np.abs(np.diff(late)) / np.diff(t_late)
    assert np.all(speed <= LIMITS.max_velocity_deg_s * (1 + 1e-9))
    ahead = late - np.interp(t_late, t_on, on)
    assert np.all(ahead >= -1e-9)
    assert np.all(ahead <= 2 * LIMITS.max_velocity_deg_s * PERIOD_S + 1e-9)


def test_the_moving_average_spans_the_same_time_with_late_ticks() -> None:
    # limits far above the step: what shapes the command is the 0.1 s average alone
    fast = KnobLimits(-1e3, 1e3, 1e6, 1e9)
    t_on, on = commands_at_times(lambda t: 0.0 if t < 0.2 else 80.0, 0, 0.5, fast)
    t_late, late = commands_at_times(lambda t: 0.0 if t < 0.2 else 80.0, 2, 0.5, fast)
    settled_on = t_on[np.argmax(on >= on[-1] - 1e-6)]
    settled_late = t_late[np.argmax(late >= late[-1] - 1e-6)]
    assert settled_late == pytest.approx(settled_on, abs=3 * PERIOD_S)


def test_a_steady_motion_is_commanded_alike_whether_ticks_are_late_or_not() -> None:
    # 30 deg/s through the loaded branch (above the dead zone): the lead along the velocity
    # estimate and the average put the command at the same place at the same time
    def ramp(t: float) -> float:
        return 30.0 + 30.0 * t

    t_on, on = commands_at_times(ramp, 0, 1.5)
    t_late, late = commands_at_times(ramp, 3, 1.5)
    tail = t_late > 0.5
    assert np.max(np.abs(late[tail] - np.interp(t_late[tail], t_on, on))) < 0.05


def test_a_staircase_of_late_ticks_gives_no_acceleration() -> None:
    # a 50 Hz client's sine seen by a loop whose ticks are 3-4 periods apart: its value
    # changes at most ticks, and its acceleration is still not readable
    kc = KnobCommand(LIMITS)
    kc.jump_deg_s = 5.0 * 1.5 * 120.0
    t_s, accel = 0.0, []
    for k in range(500):
        dt = (3 if k % 2 else 4) * PERIOD_S
        t_s += dt
        motion(kc, 60.0 * math.sin(2 * math.pi * 0.1 * math.floor(t_s * 50) / 50), dt, PERIOD_S)
        accel.append(kc.accel)
    assert max(abs(a) for a in accel) == 0.0


def client_staircase(jitter_s: float, seed: int, duration_s: float, amplitude_deg: float = 60.0,
                     f_hz: float = 0.1) -> np.ndarray:
    """The desired angle each on-time tick sees from a 50 Hz client's sine whose values arrive
    up to ``jitter_s`` late (the client thread delayed on a loaded machine): now and then two of
    them land on consecutive ticks, the staircase catching up."""
    rng = np.random.default_rng(seed)
    sent = np.arange(0.0, duration_s, 0.02)
    arrive = np.maximum.accumulate(sent + rng.uniform(0.0, jitter_s, sent.size))  # in order
    values = amplitude_deg * np.sin(2 * np.pi * f_hz * sent)
    seen = np.searchsorted(arrive, np.arange(PERIOD_S, duration_s, PERIOD_S), side="right") - 1
    return np.where(seen >= 0, values[np.maximum(seen, 0)], 0.0)


def test_a_staircase_catching_up_on_consecutive_ticks_gives_no_acceleration() -> None:
    kc = KnobCommand(LIMITS)
    kc.jump_deg_s = 5.0 * 1.5 * 120.0
    accel = []
    for q in client_staircase(0.05, 2, 10.0):
        motion(kc, float(q), PERIOD_S, PERIOD_S)
        accel.append(kc.accel)
    # the sine's own acceleration is at most 60 (2 pi 0.1)^2 = 24 deg/s^2
    assert max(abs(a) for a in accel) < 30.0


@pytest.mark.parametrize("seed", [1, 2, 4])
def test_a_jittered_client_does_not_start_the_dead_zone_jump_far_ahead(seed: int) -> None:
    # the daemon's demo on a loaded machine (the shipped simulated catheter's profile): two of
    # the client's values landing on consecutive ticks were read as ~1600 deg/s^2, and the
    # jump across the dead zone started ~0.9 s before an evenly arriving client's
    example = Path(__file__).resolve().parent.parent / "profiles" / "example-sim.yaml"
    if not example.exists():
        pytest.skip("profiles/example-sim.yaml is not there")
    config = default_sim_config()
    crossings = []
    for jitter_s in (0.0, 0.05):
        comp = make_compensator(load_profile(example), "ours", config)
        comp.reset(np.zeros(2))
        q = np.stack([client_staircase(jitter_s, seed, 20.0),
                      client_staircase(jitter_s, 100 + seed, 20.0, 30.0, 0.2)], axis=1)
        cmd = np.array([comp.command(row, PERIOD_S) for row in q])
        crossings.append([np.flatnonzero(np.diff(np.sign(cmd[:, k])) != 0) * PERIOD_S
                          for k in (0, 1)])
    for even, jittered in zip(*crossings, strict=True):
        assert len(even) == len(jittered)
        assert np.max(even - jittered) < 0.5, np.max(even - jittered)


def test_the_limiter_counts_a_late_tick_up_to_its_longest() -> None:
    limiter = KnobLimiter([LIMITS, LIMITS], PERIOD_S)
    limiter.reset(np.zeros(2))
    for _ in range(50):  # at full speed towards a far target
        limiter.limit(np.array([80.0, -80.0]))
    x0 = limiter.limit(np.array([80.0, -80.0]))
    x1 = limiter.limit(np.array([80.0, -80.0]), 10 * PERIOD_S)
    step = MAX_TICK_PERIODS * PERIOD_S * LIMITS.max_velocity_deg_s
    assert x1 - x0 == pytest.approx([step, -step])


tick_times = st.one_of(st.floats(0.0, 12 * PERIOD_S), st.just(math.nan), st.just(math.inf),
                       st.just(-PERIOD_S))


@given(random_params, st.lists(st.tuples(samples, samples, tick_times), min_size=1, max_size=80))
@settings(max_examples=50, deadline=None)
def test_late_early_or_nonsense_tick_times_keep_the_command_finite_and_within_its_speed(
        p: TensionPlayParams, rows: list[tuple[float, float, float]]) -> None:
    comp = OursCompensator(ours_knobs((p, p)), PERIOD_S, (LIMITS, LIMITS))
    comp.reset(np.zeros(2))
    last = comp.command(np.zeros(2), PERIOD_S)
    for q0, q1, dt in rows:
        cmd = comp.command(np.array([q0, q1]), dt)
        assert np.all(np.isfinite(cmd))
        assert np.all(cmd >= LIMITS.min_deg - 1e-9) and np.all(cmd <= LIMITS.max_deg + 1e-9)
        periods = max(1, round(tick_time_s(dt, PERIOD_S) / PERIOD_S))  # an early tick: one
        step = LIMITS.max_velocity_deg_s * periods * PERIOD_S
        assert np.all(np.abs(cmd - last) <= step * (1 + 1e-9) + 1e-9)
        last = cmd
