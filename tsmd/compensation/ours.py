"""Our compensator (method ``ours``): the inverse of the tension play, identified per catheter.

The model and its inverse are :mod:`tsmd.compensation.tension_play`; every catheter-specific
parameter comes from that catheter's calibration current (:mod:`tsmd.calibration.
tension_play_fit`). This module runs it once per tick for two knobs: each knob's branches
follow the other knob's command (precomputed over that angle, :mod:`tsmd.compensation.
ours_table`, so a tick only looks a row up);
the desired angle is led by the drive's lag; a jump across the dead zone is started early; the
command goes through the knob's limits and a short moving average (bounded jerk). Time is each
tick's elapsed time as the loop measured it (``dt_s``): a late tick on a loaded machine moves
the limits and the moving average on by the periods it covered, and the velocity estimates
divide by it (:mod:`tsmd.compensation.ours_knob`).

Per-tick cost matters (two knobs in well under the loop's budget): the tick uses plain floats
and lists, no numpy on scalars and no allocation beyond the output array.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from tsmd.compensation.ours_knob import (
    PLATEAU_MARGIN_DEG,
    SETTLED_DEG,
    KnobCommand,
    fresh_progress,
    motion,
    own_plane_deg,
    own_plane_plan,
    watch,
)
from tsmd.compensation.ours_table import OursKnob
from tsmd.compensation.planned import Planner
from tsmd.compensation.safety import KnobLimits, step_floats, tick_time_s
from tsmd.compensation.tension_play import (
    Branches,
    PlayState,
    interp_linear,
    inverse_step,
    model_step,
    rest_state,
)

MOVE_FROM_REST_S = 1.0
"""How long after leaving rest the look-ahead trusts the desired angle's acceleration fully."""
_MAX_LEAD_DEG = 10.0
_JUMP_MIN_DEG = 3.0


class OursCompensator:
    """Two knobs of the tension play, as a :class:`tsmd.compensation.Compensator`.

    Per tick and knob: the desired angle is led by the drive lag plus half the smoothing window;
    the inverse gives the command; a jump across a flat part seen within half the motor's
    crossing time ahead is started now and then held until the desired angle catches up (the
    crossing error is centred instead of all lag); the command then goes through the knob's
    position/velocity/acceleration limits and a moving average over ``smoothing_s``: the average
    of a feasible motion stays feasible, and its acceleration changes by at most 2 a_max per
    window, so the jerk is at most 2 a_max / ``smoothing_s``. A tick of ``dt_s`` = n periods
    steps the limits and the average n periods (the knob's target moving evenly over the
    periods missed), so limits and window hold in time, not in ticks.
    """

    def __init__(self, knobs: tuple[OursKnob, OursKnob], period_s: float,
                 limits: Sequence[KnobLimits] | None = None, smoothing_s: float = 0.1,
                 fresh_catheter: bool = False) -> None:
        if not period_s > 0:
            raise ValueError(f"period_s must be positive, got {period_s}")
        if limits is None:  # the simulated rig's drives, no position limit
            limits = (KnobLimits(-1e9, 1e9, 120.0, 2000.0),) * 2
        if len(limits) != 2:
            raise ValueError(f"need limits for 2 knobs, got {len(limits)}")
        self.knobs = knobs
        self.fresh_catheter = fresh_catheter
        """The catheter was never loaded when reset (only the bench's fresh plant, or a new
        catheter with a product profile): ``reset`` starts on the fresh branches."""
        self.period_s = period_s
        self.limits = (limits[0], limits[1])
        # jumps are planned with the slower knob's limits
        self.v_max = min(lim.max_velocity_deg_s for lim in limits)
        self.a_max = min(lim.max_accel_deg_s2 for lim in limits)
        self._n_avg = max(1, round(smoothing_s / period_s))
        self._k = (KnobCommand(self.limits[0]), KnobCommand(self.limits[1]))
        self._slot = 0
        self._planner = Planner(period_s, self.v_max, self.a_max)
        self._set_constants()
        self.reset(np.zeros(2))

    def _set_constants(self) -> None:
        # faster than any knob can make the tip move (release slope <= 5 omega T')
        jump_deg_s = 5.0 * max(k.omega * k.steepest_shape_slope for k in self.knobs) * self.v_max
        self._gains = (self.knobs[0].other_tip_gain, self.knobs[1].other_tip_gain)
        self._plan_source: object = None
        self._plan_own: list[list[float]] = []
        for kc, knob in zip(self._k, self.knobs, strict=True):
            kc.ahead_s = knob.lag_s + 0.5 * (self._n_avg - 1) * self.period_s
            kc.ahead_ticks = round(kc.ahead_s / self.period_s)
            kc.jump_deg_s = jump_deg_s
            kc.omega = knob.omega
            kc.plateau_lo_deg = min(knob.height_pos_deg, knob.height_neg_deg)
            kc.plateau_hi_deg = max(knob.height_pos_deg, knob.height_neg_deg)
            kc.fresh_hi_deg = knob.height_neg_deg
            kc.fresh_lo_deg = knob.height_pos_deg
            kc.home_hold = knob.hold_at_home  # the product's choice (tsmd datasheet --home-hold)

    def replace_knobs(self, knobs: tuple[OursKnob, OursKnob]) -> None:
        """New parameters from the next tick on, state kept (online re-estimation)."""
        self.knobs = knobs
        self._set_constants()

    def reset(self, q_deg: NDArray[np.float64]) -> None:
        """At rest at ``q_deg``. On a fresh catheter (``fresh_catheter``: straight, never
        loaded) a knob whose profile knows the fresh hold (``fresh_hold_deg``) uses the fresh
        branches until its first release has ended."""
        q = [float(v) if math.isfinite(v) else 0.0 for v in np.asarray(q_deg, dtype=float)]
        q = [own_plane_deg(q[0], q[1], self._gains[0]), own_plane_deg(q[1], q[0], self._gains[1])]
        fresh = [self.fresh_catheter and k.is_fresh_known for k in self.knobs]
        x = [0.0, 0.0]
        states = [PlayState(0.0, 0.0, 1, 0.0)] * 2
        for _ in range(3):  # each knob's branches depend on the other knob's command
            states = [rest_state(q[i], self.knobs[i].at(x[1 - i], fresh[i])) for i in (0, 1)]
            x = [s.x_deg for s in states]
        for i in (0, 1):
            self._k[i].reset(states[i], q[i], self._n_avg)
            self._k[i].fresh = fresh[i]
            self._k[i].first_side = 0
        self._slot = 0

    def preview(self, plan_deg: Sequence[Sequence[float]], index: int) -> None:
        """This tick's desired angles are ``plan_deg[index]`` and the ones after it follow
        (the loop playing a trajectory says so every tick; without it the next command is
        causal): the dead-zone crossings and sharp turns are then timed on the plan
        (:class:`tsmd.compensation.planned.Planner`)."""
        gains = self._gains
        if gains != (0.0, 0.0):  # the plan as each knob's model must give it, made once
            if plan_deg is not self._plan_source:
                self._plan_source, self._plan_own = plan_deg, own_plane_plan(plan_deg, gains)
            plan_deg = self._plan_own
        self._planner.set(plan_deg, index)

    def command(self, q_deg: NDArray[np.float64], dt_s: float) -> NDArray[np.float64]:
        """The motor command for the desired angles ``q_deg``, ``dt_s`` after the last tick."""
        k0, k1 = self._k
        b0 = self.knobs[0].at(k1.state.x_deg, k0.fresh, k0.first_side)
        b1 = self.knobs[1].at(k0.state.x_deg, k1.fresh, k1.first_side)
        period = self.period_s
        dt, n = self._elapsed(dt_s)
        planner = self._planner
        planned = planner.take()
        out = []
        q0, q1 = float(q_deg[0]), float(q_deg[1])
        g0, g1 = self._gains
        for col, kc, qi, b in ((0, k0, own_plane_deg(q0, q1, g0), b0),
                               (1, k1, own_plane_deg(q1, q0, g1), b1)):
            if qi - qi == 0.0:  # finite; otherwise the command stays where it is
                self._track(kc, qi, b, planned, dt)
                if planned:
                    kc.out = planner.command(kc.plan, kc.state, kc.out, kc.ahead_ticks, col, b)
                if kc.fresh:
                    fresh_progress(kc)
            if n == 1:
                x, kc.lim_v, kc.lim_target = step_floats(kc.lim_deg, kc.lim_v, kc.lim_target,
                                                         kc.out, kc.limits, period)
                kc.lim_deg = x
                window = kc.window
                kc.sum += x - window[self._slot]
                window[self._slot] = x
            else:
                self._catch_up(kc, n)
            out.append(kc.sum)
        slot = self._slot + n
        n_avg = self._n_avg
        self._slot = slot if slot < n_avg else slot % n_avg
        return np.array((out[0] / n_avg, out[1] / n_avg))

    def _elapsed(self, dt_s: float) -> tuple[float, int]:
        """This tick's time (seconds, :func:`tick_time_s`) and the whole periods it covers
        (at least one)."""
        period = self.period_s
        if dt_s == period:
            return period, 1
        dt = tick_time_s(dt_s, period)
        n = int(dt / period + 0.5)
        return dt, n if n > 1 else 1

    def _catch_up(self, kc: KnobCommand, n: int) -> None:
        """``n`` periods of the limits and the average in one tick: the target moved evenly
        from the last one to ``kc.out`` over them."""
        period = self.period_s
        start = kc.lim_target if kc.lim_target is not None else kc.out
        goal = kc.out
        window, n_avg = kc.window, self._n_avg
        slot = self._slot
        for j in range(1, n + 1):
            target = goal if j == n or goal - goal != 0.0 else start + (goal - start) * j / n
            x, kc.lim_v, kc.lim_target = step_floats(kc.lim_deg, kc.lim_v, kc.lim_target,
                                                     target, kc.limits, period)
            kc.lim_deg = x
            kc.sum += x - window[slot]
            window[slot] = x
            slot = slot + 1 if slot + 1 < n_avg else 0

    def follow(self, q_deg: NDArray[np.float64], motor_deg: NDArray[np.float64],
               dt_s: float) -> None:
        """Someone else sent the motor ``motor_deg`` for ``q_deg``, ``dt_s`` after the last
        tick: the model follows the motor, the trackers ``q_deg``, the output filter holds the
        motor (a switch continues here)."""
        period = self.period_s
        dt, _ = self._elapsed(dt_s)
        for i, kc in enumerate(self._k):
            qi = own_plane_deg(float(q_deg[i]), float(q_deg[1 - i]), self._gains[i])
            x = float(motor_deg[i])
            if qi - qi == 0.0:
                watch(kc, qi, dt, self._n_avg)
                motion(kc, qi, dt, period)
                kc.target = qi
                kc.still_s = 0.0  # no dwell before this compensator has brought the tip to q
            if x - x == 0.0:
                b = self.knobs[i].at(float(motor_deg[1 - i]), kc.fresh, kc.first_side)
                kc.state = model_step(kc.state, x, b)
                if kc.fresh:
                    fresh_progress(kc)
                kc.out = x
                kc.hold = 0
                kc.plan.direction = 0  # a planned crossing is this compensator's own
                kc.lim_v, kc.lim_deg, kc.lim_target = (x - kc.lim_deg) / dt, x, None
                kc.window = [x] * self._n_avg  # the filter's output is the motor's command
                kc.sum = x * self._n_avg

    def continue_from(self, other: OursCompensator) -> None:
        """Take ``other``'s state (same catheter), keep these parameters."""
        self._k = copy.deepcopy(other._k)
        self._slot = other._slot
        self._set_constants()

    def _track(self, kc: KnobCommand, q_raw: float, b: Branches, planned: bool,
               dt_s: float) -> None:
        still = -SETTLED_DEG < q_raw - kc.q_tick < SETTLED_DEG
        kc.q_tick = q_raw
        if watch(kc, q_raw, dt_s, self._n_avg) and self._centre(kc, b):
            return
        before, out_before = kc.state, kc.out
        qi, dq, v = motion(kc, q_raw, dt_s, self.period_s)
        lead = kc.ahead_s * v
        if lead < -_MAX_LEAD_DEG:
            lead = -_MAX_LEAD_DEG
        elif lead > _MAX_LEAD_DEG:
            lead = _MAX_LEAD_DEG
        target = qi + lead
        # The lead shrinks as the desired angle slows; it must never turn the target back while
        # the desired angle itself does not turn: a false reversal jumps across the backlash.
        step = target - kc.target
        state = kc.state
        if step * dq < 0.0 or (dq == 0.0 and step * state.direction < 0.0):
            target = kc.target
        kc.target = target
        state = inverse_step(state, target, b)
        kc.state = state
        kc.out = state.x_deg if planned else self._early_jump(kc, state, target, v, b)
        if still and kc.home_hold and state.x_deg != before.x_deg:
            _keep_at_home(kc, before, out_before, b)

    def _centre(self, kc: KnobCommand, b: Branches) -> bool:
        """During a dwell: the knob to the middle of the play holding the model's output (the
        other knob may move the branches: recomputed every tick). Not at rest on a plateau
        (both tendons slack, the catheter at home): there the knob is never moved on its own."""
        state = kc.state
        y = state.y_deg
        if kc.plateau_lo_deg - PLATEAU_MARGIN_DEG <= y <= kc.plateau_hi_deg + PLATEAU_MARGIN_DEG:
            return False
        x = 0.5 * (interp_linear(y, b.falling_deg, b.knots)
                   + interp_linear(y, b.rising_deg, b.knots))
        kc.state = PlayState(x, y, state.direction, y)
        kc.v = kc.v_raw = kc.accel = 0.0
        kc.hold = 0
        kc.out = x
        return True

    def _early_jump(self, kc: KnobCommand, state: PlayState, target: float, v: float,
                    b: Branches) -> float:
        x, d = state.x_deg, state.direction
        prev = kc.out
        if kc.hold != 0:
            if kc.hold == d and (x - prev) * d < 0.0:
                return prev  # the desired angle has not caught up with the early jump yet
            kc.hold = 0
        speed = abs(v)
        if speed < 1e-3 or (v > 0) != (d > 0):
            return x
        # moving on in direction d: the inverse ahead is the branch's inverse, never behind x
        ys = b.rising_deg if d > 0 else b.falling_deg
        horizon_s = 30.0 / self.v_max  # half the crossing time of a 60 deg jump
        # a desired angle speeding up (the start of a move) gets there sooner than v says; no
        # faster than the knob itself can speed up (beyond that it is a step, not a motion)
        accel = kc.accel if kc.accel * v > 0.0 else 0.0
        # Early in a move from rest, the crossing is timed so that the error it leaves at its
        # start and at its end are equal: it starts when the mean of the desired angle now and
        # at the horizon end passes the flat (a move from rest speeds up: centring on the time
        # the desired angle passes the flat left errors of +9 / -20 deg). Elsewhere (a
        # continuous motion: its acceleration is no trend) centred in time as before.
        gain = 1.0 if kc.move_s < MOVE_FROM_REST_S else 0.5
        a_max = self.a_max
        if accel > a_max:
            accel = a_max
        elif accel < -a_max:
            accel = -a_max
        ahead = x
        for _ in range(2):
            travel = (v + gain * accel * horizon_s) * horizon_s
            ahead = interp_linear(target + travel, ys, b.knots)
            if (ahead - x) * d < 0.0:
                ahead = x
            expected = abs(travel) / kc.omega  # the knob moves that much on a loaded line
            jump = (ahead - x) * d - expected
            if jump <= expected + _JUMP_MIN_DEG:
                return x
            horizon_s = 0.5 * (jump / self.v_max + self.v_max / self.a_max)
        kc.hold = d
        return ahead


def _keep_at_home(kc: KnobCommand, before: PlayState, out_before: float, b: Branches) -> None:
    """A knob whose desired angle has not moved, its output inside the plateau band (at home:
    the band :meth:`OursCompensator._centre` leaves alone), keeps its knob while the play at
    that knob still holds the output: the other knob moved this knob's branches (a level grid
    shifts the loaded branch with the other knob's angle), and following the moved branch
    pulls a rope whose tip the other plane's load holds where it was (pronyring's ring seat:
    development 2 phi1's tip error 0.75 -> 2.07 deg rms with the grid while phi2 swept
    past +-60)."""
    state = kc.state
    y = state.y_deg
    if not kc.plateau_lo_deg - PLATEAU_MARGIN_DEG <= y <= kc.plateau_hi_deg + PLATEAU_MARGIN_DEG:
        return
    x = before.x_deg
    if interp_linear(x, b.knots, b.rising_deg) <= y <= interp_linear(x, b.knots, b.falling_deg):
        kc.state = before._replace(y_deg=y, held_deg=y)
        kc.out = out_before
