"""One knob's command state in our compensator, and how it reads the desired angle.

The tick (:mod:`tsmd.compensation.ours`) keeps each knob's state in a :class:`KnobCommand` of
plain floats; :func:`watch` and :func:`motion` read the desired angle into it: rest and dwell
bookkeeping, the jitter deadband, the velocity and acceleration estimates. The compensator's
tick and its standing by (``follow``) share them, so that a switch continues where the tick
would have been. Time is the elapsed time of each tick (``dt_s``, what the loop measured), not a
count of ticks: on a loaded machine a late tick carries two or three periods of the desired
angle's motion, and read as one period it doubled or tripled the velocity estimate.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from tsmd.compensation.fresh_play import fresh_state_ends
from tsmd.compensation.planned import PlanHold
from tsmd.compensation.safety import KnobLimits
from tsmd.compensation.tension_play import PlayState

PLATEAU_MARGIN_DEG = 1.0
"""An output this far beyond the plateaus is off them (a loaded side, not the dead zone)."""

REVERSAL_DEADBAND_DEG = 0.1
"""A desired angle that turns back by less than this is held: an exact inverse would make the
motor cross the whole backlash for every jitter of the operator's input (error <= this)."""
DWELL_S = 0.4
"""A desired angle standing still (within :data:`REVERSAL_DEADBAND_DEG`) this long after the
command arrived, off the plateaus, is a dwell:
the knob moves to the middle of the play that holds the tip there (the tip does not move), so
the next move, whichever way it goes, crosses half the play instead of all of it (a causal
feed-forward cannot know the direction: the middle halves the worse case)."""
REST_S = 0.4
REST_DEG = 0.01
"""A desired angle standing this long within this band is at rest: the next motion is a move
from rest (point-to-point), which speeds up along a planned profile. A continuous motion's
turning points stand within the reversal deadband for 0.2-1.2 s (the multisine): not rests."""
SETTLED_DEG = 1e-3
"""The sent command has arrived when the output filter is this close to it."""


class KnobCommand:
    """One knob's command state (slots: the tick reads and writes these attributes only)."""

    __slots__ = ("accel", "ahead_s", "ahead_ticks", "first_side", "fresh", "fresh_hi_deg",
                 "fresh_lo_deg", "held_s", "hold", "home_hold", "jump_deg_s", "lim_deg",
                 "lim_target", "lim_v", "limits", "move_s", "omega", "out", "plan",
                 "plateau_hi_deg", "plateau_lo_deg", "q_dir", "q_prev", "q_raw", "q_tick", "rest_q",
                 "stand_s", "state", "still_q", "still_s", "sum", "target", "v", "v_raw",
                 "v_raw_known", "window")

    def __init__(self, limits: KnobLimits) -> None:
        self.limits = limits
        self.ahead_s = 0.0
        self.ahead_ticks = 0
        self.plan = PlanHold()
        self.jump_deg_s = 0.0
        """A desired angle faster than this (deg/s) steps: nothing to predict from it."""
        self.omega = 1.0
        self.plateau_lo_deg = self.plateau_hi_deg = 0.0
        self.fresh = False
        """Still on a fresh catheter's branches (its first release has not ended)."""
        self.first_side = 0
        """The side a fresh knob loaded first (+1, -1; 0: not yet)."""
        self.fresh_hi_deg = self.fresh_lo_deg = 0.0
        """Where a fresh knob's first release has ended (the falling / rising plateau)."""
        self.home_hold = False
        """This knob keeps its command at rest in its plateau band (the product's choice)."""
        self.reset(PlayState(0.0, 0.0, 1, 0.0), 0.0, 1)

    def reset(self, state: PlayState, q_deg: float, n_avg: int) -> None:
        self.state = state
        self.q_prev = q_deg
        self.q_dir = state.direction
        self.v = 0.0
        self.accel = 0.0
        self.q_raw = q_deg
        self.q_tick = q_deg
        """The desired angle the last tick tracked (every tick, a dwell's too)."""
        self.v_raw = 0.0
        self.v_raw_known = True
        """``v_raw`` is a velocity the next change may be compared with (the desired angle
        stood at rest, or changed every period): only then is a change an acceleration."""
        self.held_s = 0.0
        self.target = q_deg
        self.out = state.x_deg
        self.hold = 0
        self.plan.direction = 0
        self.still_q = q_deg
        self.still_s = 0.0
        self.rest_q = q_deg
        self.stand_s = 0.0
        self.move_s = math.inf
        x = self.limits.clip(state.x_deg)
        # the limiter's state as plain floats (safety.step_floats): no object per tick
        self.lim_deg = x
        self.lim_v = 0.0
        self.lim_target: float | None = None
        self.window = [x] * n_avg
        self.sum = x * n_avg


def watch(kc: KnobCommand, q_raw: float, dt_s: float, n_avg: int) -> bool:
    """Rest and dwell bookkeeping of the desired angle over ``dt_s`` (this tick's elapsed
    time); True when a dwell is due."""
    kc.move_s += dt_s
    if -REST_DEG < q_raw - kc.rest_q < REST_DEG:
        kc.stand_s += dt_s
    else:
        if kc.stand_s >= REST_S:
            kc.move_s = 0.0  # a move from rest starts
        kc.stand_s = 0.0
        kc.rest_q = q_raw
    if -REVERSAL_DEADBAND_DEG < q_raw - kc.still_q < REVERSAL_DEADBAND_DEG:
        # the dwell counts once the sent command has arrived (the tip got there first)
        if abs(kc.sum / n_avg - kc.out) < SETTLED_DEG:
            kc.still_s += dt_s
        return kc.still_s >= DWELL_S
    kc.still_q = q_raw
    kc.still_s = 0.0
    return False


def motion(kc: KnobCommand, q_raw: float, dt_s: float, period_s: float
           ) -> tuple[float, float, float]:
    """The desired angle past the jitter deadband, its step and its velocity estimate, over
    this tick's elapsed time ``dt_s``. The estimates are first-order filters whose time
    constants are set in periods (0.7 and 0.8 kept per period): a tick of n periods keeps
    0.7^n, as n ticks of constant velocity would."""
    if dt_s == period_s:
        keep_v, gain_v, keep_a, gain_a = 0.7, 0.3, 0.8, 0.2
    else:
        keep_v, keep_a = 0.7 ** (dt_s / period_s), 0.8 ** (dt_s / period_s)
        gain_v, gain_a = 1.0 - keep_v, 1.0 - keep_a
    q_prev = kc.q_prev
    qi = q_prev
    if (q_raw - q_prev) * kc.q_dir >= 0.0:
        qi = q_raw
    elif abs(q_raw - q_prev) >= REVERSAL_DEADBAND_DEG:  # a reversal, not jitter
        qi = q_raw
        kc.q_dir = -kc.q_dir
    dq = qi - q_prev
    kc.q_prev = qi
    v = keep_v * kc.v + gain_v * dq / dt_s
    jump_deg = kc.jump_deg_s * dt_s
    if abs(dq) > jump_deg:  # a step, not a motion: nothing to predict from it
        v = 0.0
    kc.v = v
    # The acceleration from the desired angle itself (the jitter deadband above releases a
    # held input in one step, which is no acceleration of the operator's hand), only from a
    # desired angle that changes every tick (a trajectory played in the loop). A client
    # that sets 50 times a second holds each value for several ticks with its own timing
    # jitter: the velocity of that staircase is readable, its acceleration is not (the
    # daemon's demo: RMSE 11.4 / 6.8 deg with it, 3.0 / 3.0 without). "Every tick" is every
    # period, in time: ticks late by a period or more let that client's staircase change at
    # nearly every tick, and its acceleration then was noise up to the knob's limit again.
    # A held value is zero velocity only when the angle stood at rest: after a staircase's
    # short hold (or a late tick) the next change in the very next period is the staircase
    # catching up, not the hand speeding up from zero. Read as one (the demo under load: two
    # of the client's values landing on consecutive ticks), it gave ~1600 deg/s^2, the early
    # jump crossed the dead zone ~0.8 s ahead and held there: phi1 RMSE 8-11 deg in one run
    # of ten. Such a change starts the velocity afresh, with no acceleration.
    dq_raw = q_raw - kc.q_raw
    kc.held_s += dt_s
    if dq_raw != 0.0:
        kc.q_raw = q_raw
        if abs(dq_raw) > jump_deg or kc.held_s > 1.5 * period_s:
            kc.v_raw = kc.accel = 0.0  # a step, a staircase, or a start after a pause
            kc.v_raw_known = abs(dq_raw) <= jump_deg and kc.held_s >= REST_S
        elif kc.v_raw_known:
            v_raw = keep_v * kc.v_raw + gain_v * dq_raw / dt_s
            kc.accel = keep_a * kc.accel + gain_a * (v_raw - kc.v_raw) / dt_s
            kc.v_raw = v_raw
        else:
            kc.v_raw = dq_raw / dt_s
            kc.accel = 0.0
            kc.v_raw_known = True
        kc.held_s = 0.0
    elif kc.held_s > 1.5 * period_s:
        kc.v_raw = kc.accel = 0.0  # standing: the next move starts from rest
    return qi, dq, v


def own_plane_deg(q_deg: float, other_q_deg: float, other_tip_gain: float) -> float:
    """What one knob's model must give for the tip to reach ``q_deg`` in its plane: a shaft
    that turns the planes into each other adds ``other_tip_gain`` times the other plane's tip
    angle (the other knob's desired angle: its compensation brings the tip there). Without a
    gain, or with a non-finite other angle, the desired angle itself."""
    if other_tip_gain == 0.0 or other_q_deg - other_q_deg != 0.0:
        return q_deg
    return q_deg - other_tip_gain * other_q_deg


def own_plane_plan(plan_deg: Sequence[Sequence[float]], gains: tuple[float, float]
                   ) -> list[list[float]]:
    """A played trajectory's rows as each knob's model must give them (:func:`own_plane_deg`)."""
    g0, g1 = gains
    return [[own_plane_deg(float(r[0]), float(r[1]), g0),
             own_plane_deg(float(r[1]), float(r[0]), g1)] for r in plan_deg]


def fresh_progress(kc: KnobCommand) -> None:
    """Which side a fresh knob loaded first, and whether its first release has ended."""
    y = kc.state.y_deg
    if kc.first_side == 0:
        if y > kc.plateau_hi_deg + PLATEAU_MARGIN_DEG:
            kc.first_side = 1
        elif y < kc.plateau_lo_deg - PLATEAU_MARGIN_DEG:
            kc.first_side = -1
    elif fresh_state_ends(kc.state, kc.first_side, kc.fresh_hi_deg, kc.fresh_lo_deg):
        kc.fresh = False
