"""The last stage before the drives: position limits, velocity and acceleration limits.

An inverse hysteresis model jumps across the dead zone and the backlash; a real motor cannot.
The limiter turns any command into one the knob can follow: it never leaves the knob's range,
its speed never exceeds ``max_velocity_deg_s`` and its speed changes by at most
``max_accel_deg_s2 * dt_s`` per tick; it brakes in time to stop on the target without overshoot.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

DEFAULT_MAX_VELOCITY_DEG_S = 120.0
"""Knob speed limit when the configuration does not say (the simulated rig's data sheet)."""
DEFAULT_MAX_ACCEL_DEG_S2 = 2000.0
"""Knob acceleration limit when the configuration does not say."""
MAX_TICK_PERIODS = 4
"""A late tick is given the time it covers, up to this many periods, for what counts time
(the compensator's estimates, timers and averages). Longer is a stall (a streak of overruns
faults the loop), not motion time. The loop's own limiter still steps one period per SYNC: a
CSP drive moves to each target over its interpolation period."""


@dataclass(frozen=True)
class KnobLimits:
    """One knob's motion limits (data-sheet constants of the device)."""

    min_deg: float
    max_deg: float
    max_velocity_deg_s: float
    max_accel_deg_s2: float

    def __post_init__(self) -> None:
        values = (self.min_deg, self.max_deg, self.max_velocity_deg_s, self.max_accel_deg_s2)
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f"knob limits must be finite, got {values}")
        if self.min_deg >= self.max_deg:
            raise ValueError(f"min_deg {self.min_deg} must be below max_deg {self.max_deg}")
        if self.max_velocity_deg_s <= 0 or self.max_accel_deg_s2 <= 0:
            raise ValueError("max_velocity_deg_s and max_accel_deg_s2 must be positive")

    def clip(self, q_deg: float) -> float:
        return min(max(q_deg, self.min_deg), self.max_deg)


class LimiterState(NamedTuple):
    """Where the limited command is, how fast it moves, and the last target it was given
    (a named tuple: one is made per knob and tick)."""

    q_deg: float
    v_deg_s: float = 0.0
    target_deg: float | None = None


def limit_step(state: LimiterState, target_deg: float, limits: KnobLimits,
               dt_s: float) -> LimiterState:
    """One tick of the limiter: move toward ``target_deg`` as fast as the limits allow.

    A target that moves feasibly (within the velocity limit) is followed without lag: the
    limiter brakes relative to the target's own motion, not as if it were about to stop. A
    non-finite target holds the current position (it never reaches the motor).
    """
    if dt_s <= 0:
        raise ValueError(f"dt_s must be positive, got {dt_s}")
    return LimiterState(*step_floats(state.q_deg, state.v_deg_s, state.target_deg, target_deg,
                                     limits, dt_s))


def step_floats(q0: float, v0: float, last_target: float | None, target_deg: float,
                limits: KnobLimits, dt_s: float) -> tuple[float, float, float]:
    """:func:`limit_step` on plain floats (the loop's hot path: no object per tick; plain
    comparisons instead of min/max and clip)."""
    a = limits.max_accel_deg_s2
    v_max = limits.max_velocity_deg_s
    lo, hi = limits.min_deg, limits.max_deg
    finite = target_deg - target_deg == 0.0
    target = q0
    if finite:
        target = lo if target_deg < lo else (hi if target_deg > hi else target_deg)
    v_target = 0.0
    if last_target is not None and finite:
        v_target = (target - last_target) / dt_s
        if abs(v_target) > 1.05 * v_max:  # a jump, not a motion: chase it as standing still
            v_target = 0.0
    d = target - q0
    # The fastest approach speed from which the discrete decelerating sequence still stops on
    # the target (relative to its own motion).
    half_a_dt = 0.5 * a * dt_s
    v_stop = math.sqrt(half_a_dt * half_a_dt + 2.0 * a * abs(d)) - half_a_dt
    v_want = d / dt_s  # reach the target in this tick if the limits allow
    if d >= 0.0:
        if v_want - v_target > v_stop:  # closing in too fast to stop
            v_want = v_target + v_stop
    elif v_target - v_want > v_stop:
        v_want = v_target - v_stop
    dv = a * dt_s
    v = v0 - dv if v_want < v0 - dv else (v0 + dv if v_want > v0 + dv else v_want)
    v = -v_max if v < -v_max else (v_max if v > v_max else v)
    q = q0 + v * dt_s
    if q < lo or q > hi:  # position first, whatever the speed
        q = lo if q < lo else hi
        v = (q - q0) / dt_s
    return q, v, target


class KnobLimiter:
    """The limiter of both knobs, stateful: :func:`limit_step` once per knob and tick.

    The one limiter of tsmd: the control loop applies it last, and
    :class:`tsmd.compensation.LimitedCompensator` puts it behind a compensator offline.
    """

    def __init__(self, limits: Sequence[KnobLimits], dt_s: float) -> None:
        if len(limits) != 2:
            raise ValueError(f"need limits for 2 knobs, got {len(limits)}")
        if not dt_s > 0:
            raise ValueError(f"dt_s must be positive, got {dt_s}")
        self.limits = tuple(limits)
        self.dt_s = dt_s
        self._states: list[tuple[float, float, float | None]] = [(0.0, 0.0, None)] * 2

    def reset(self, cmd_deg: NDArray[np.float64], *, hold: bool = False) -> None:
        """Stand still at ``cmd_deg``; ``hold``: also take it as the last target (no jump)."""
        self._states = [(float(q), 0.0, float(q) if hold else None) for q in cmd_deg]

    def limit(self, cmd_deg: NDArray[np.float64], dt_s: float | None = None
              ) -> NDArray[np.float64]:
        """The limited command, ``dt_s`` after the last (default and on time: one period)."""
        return np.array(self.limit_pair(float(cmd_deg[0]), float(cmd_deg[1]), dt_s))

    def limit_pair(self, cmd0_deg: float, cmd1_deg: float, dt_s: float | None = None
                   ) -> tuple[float, float]:
        """:meth:`limit` on two floats (the control loop's hot path: no arrays)."""
        dt = self.dt_s if dt_s is None else tick_time_s(dt_s, self.dt_s)
        lim0, lim1 = self.limits
        s0, s1 = self._states
        s0 = step_floats(s0[0], s0[1], s0[2], cmd0_deg, lim0, dt)
        s1 = step_floats(s1[0], s1[1], s1[2], cmd1_deg, lim1, dt)
        self._states = [s0, s1]
        return s0[0], s1[0]


def tick_time_s(dt_s: float, period_s: float) -> float:
    """The time a tick counts for: its elapsed ``dt_s``, at most :data:`MAX_TICK_PERIODS`
    periods; one period if ``dt_s`` is not a positive number."""
    if dt_s == period_s:
        return period_s
    if not dt_s > 0.0 or dt_s - dt_s != 0.0:
        return period_s
    longest = MAX_TICK_PERIODS * period_s
    return dt_s if dt_s < longest else longest
