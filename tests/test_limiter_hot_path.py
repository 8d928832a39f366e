"""The loop's limiter (plain floats per tick) is limit_step, knob by knob, bit for bit."""

from __future__ import annotations

import numpy as np

from tsmd.compensation.safety import KnobLimiter, KnobLimits, LimiterState, limit_step

LIMITS = (KnobLimits(-120.0, 120.0, 120.0, 2000.0), KnobLimits(-90.0, 90.0, 80.0, 1500.0))
DT = 0.004


def test_knob_limiter_equals_limit_step_on_each_knob_over_jumps_and_ramps() -> None:
    rng = np.random.default_rng(4)
    targets = np.cumsum(rng.normal(0.0, 2.0, (600, 2)), axis=0)
    targets[::97] += rng.uniform(-150.0, 150.0, (len(targets[::97]), 2))  # jumps, some beyond
    targets[300] = [np.nan, np.inf]
    limiter = KnobLimiter(LIMITS, DT)
    limiter.reset(np.array([5.0, -3.0]))
    states = [LimiterState(5.0), LimiterState(-3.0)]
    for target in targets:
        out = limiter.limit(target)
        states = [limit_step(s, float(t), lim, DT)
                  for s, t, lim in zip(states, target, LIMITS, strict=True)]
        assert out.tolist() == [s.q_deg for s in states]


def test_knob_limiter_reset_with_hold_takes_the_position_as_the_last_target() -> None:
    limiter = KnobLimiter(LIMITS, DT)
    limiter.reset(np.array([10.0, 20.0]), hold=True)
    held = limiter.limit(np.array([10.0, 20.0]))
    assert held.tolist() == [10.0, 20.0]


def test_limit_pair_equals_limit() -> None:
    rng = np.random.default_rng(7)
    targets = np.cumsum(rng.normal(0.0, 3.0, (300, 2)), axis=0)
    by_array, by_pair = KnobLimiter(LIMITS, DT), KnobLimiter(LIMITS, DT)
    for target in targets:
        assert by_array.limit(target).tolist() == list(by_pair.limit_pair(*target.tolist()))
