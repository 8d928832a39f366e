"""Ours with a plan: dead-zone crossings and sharp turns timed on the desired angles to come.

When the loop plays a trajectory it hands the compensator the whole table every tick
(:class:`tsmd.compensation.Previewing`). The tip stands still while the knob crosses a dead
zone or a backlash, whatever the knob does, and the knob crosses at most at its velocity limit:
the least peak error is the one that balances the error when the tip stops against the error
when it moves again. A causal compensator can only guess when that is (a prediction of a move
from rest, tried in session 8, was no better than :meth:`OursCompensator._early_jump`'s
heuristic); with the plan it is read, not guessed.

Per-tick cost: a handful of table reads and two interpolations on <= 8 knots per knob.
"""

from __future__ import annotations

from collections.abc import Sequence

from tsmd.compensation.tension_play import Branches, PlayState, interp_linear

HORIZON_S = 1.0
"""How far ahead the plan is read (the widest crossing takes < 0.5 s)."""
TURN_MIN_DEG = 1.0
"""A turn is taken early only if the balanced error is at least this (a third of what the
causal reversal leaves at a triangle's turn): where the turn is slow both are small, and an
early start only moves the model's backlash error into the tip."""
_TURN_SAMPLES = 8  # the plan read at this many points across a backlash crossing
_MIN_DEG = 3.0  # narrower crossings are left to the inverse
_HOLD_MARGIN_S = 0.1


class PlanHold:
    """One knob's planned crossing in progress: the command held at ``out_deg`` (direction
    ``direction``, 0: none) until the model's knob catches up, at the latest at plan row
    ``until``."""

    __slots__ = ("direction", "out_deg", "until")

    def __init__(self) -> None:
        self.direction = 0
        self.out_deg = 0.0
        self.until = 0


class Planner:
    """The plan of the present tick and the crossings timed on it, for both knobs."""

    __slots__ = ("a_max", "fresh", "index", "period_s", "plan", "v_max")

    def __init__(self, period_s: float, v_max: float, a_max: float) -> None:
        self.period_s = period_s
        self.v_max = v_max
        self.a_max = a_max
        self.plan: Sequence[Sequence[float]] = ()
        self.index = 0
        self.fresh = False

    def set(self, plan_deg: Sequence[Sequence[float]], index: int) -> None:
        self.plan = plan_deg
        self.index = index
        self.fresh = True

    def take(self) -> bool:
        """Whether this tick has a plan (a plan counts for the tick it was given only)."""
        fresh = self.fresh
        self.fresh = False
        return fresh and len(self.plan) > 0

    def command(self, hold: PlanHold, state: PlayState, out: float, ahead_ticks: int,
                col: int, b: Branches) -> float:
        """The knob's command: ``out`` (the causal one) unless a planned crossing holds it or
        starts now. ``ahead_ticks``: when the command shows at the tip (drive lag + half the
        smoothing window); ``col``: the knob's column in the plan."""
        x = state.x_deg
        if hold.direction != 0:
            if (x - hold.out_deg) * hold.direction < 0.0 and self.index <= hold.until:
                return hold.out_deg  # the desired angle has not caught up with the jump yet
            hold.direction = 0  # caught up, or the plan's time for it is over (it turned again)
        plan, period = self.plan, self.period_s
        last = len(plan) - 1
        k0 = self.index + ahead_ticks
        q_now = plan[k0 if k0 < last else last][col]
        if q_now - q_now != 0.0:
            return out  # a plan that is not finite here is no plan
        turn = self._turn(hold, state, col, b, k0, q_now)
        if turn is not None:
            return turn
        k = k0 + round(HORIZON_S / period)
        q_far = plan[k if k < last else last][col]
        if abs(q_far - q_now) < _MIN_DEG:
            return out  # the plan stands (or hardly moves) for the next second
        d = 1 if q_far > q_now else -1
        flat = b.rising_flat if d > 0 else b.falling_flat
        if flat is None or (q_now - flat.y_deg) * d >= 0.0:
            return out  # no dead zone ahead, or the desired angle is past its plateau
        entry, exit_ = (flat.lo_deg, flat.hi_deg) if d > 0 else (flat.hi_deg, flat.lo_deg)
        width = (exit_ - x) * d
        to_entry = (entry - x) * d
        if to_entry > 0.0:
            width -= to_entry
        else:
            to_entry = 0.0
        if width < _MIN_DEG:
            return out  # past the dead zone (or all but through it)
        # when the knob, sent now, reaches the plateau and leaves it (speeding up to v_max
        # costs half the time the acceleration takes)
        v_max = self.v_max
        t_in = 0.5 * v_max / self.a_max + to_entry / v_max
        t_out = t_in + width / v_max
        if t_out > HORIZON_S:
            return out
        k = k0 + round(t_in / period)
        q_in = plan[k if k < last else last][col]
        k = k0 + round(t_out / period)
        q_out = plan[k if k < last else last][col]
        if (q_in + q_out - 2.0 * flat.y_deg) * d < 0.0 or not q_in - q_in == q_out - q_out == 0.0:
            return out  # too early: the tip would wait on the plateau ahead of the plan
        ahead = interp_linear(q_out, b.rising_deg if d > 0 else b.falling_deg, b.knots)
        if (ahead - exit_) * d <= 0.0:
            return out  # the plan stops before the dead zone's far end: no jump
        return self._hold(hold, d, ahead, t_out)

    def _turn(self, hold: PlanHold, state: PlayState, col: int, b: Branches, k0: int,
              q_now: float) -> float | None:
        """The knob across the backlash before the plan turns back, or None. The tip holds
        while the knob crosses: started so that the error at the turn's peak equals the error
        when the crossing ends (a triangle's turn: a third of the crossing time early); the
        knob then goes on to where the plan is at that end."""
        d = state.direction
        ys = b.falling_deg if d > 0 else b.rising_deg  # the branch after the turn
        x_end = interp_linear(q_now, ys, b.knots)
        width = (state.x_deg - x_end) * d
        if width < _MIN_DEG:
            return None  # no backlash to cross (or the knob is already across)
        t_b = 0.5 * self.v_max / self.a_max + width / self.v_max
        if t_b > HORIZON_S:
            return None
        plan = self.plan
        last = len(plan) - 1
        n = round(t_b / self.period_s)
        k = k0 + n
        q_end = plan[k if k < last else last][col]
        if (q_end - q_now) * d >= 0.0:
            return None  # the plan does not turn back within the crossing
        peak = q_now
        for j in range(1, _TURN_SAMPLES):
            k = k0 + n * j // _TURN_SAMPLES
            qj = plan[k if k < last else last][col]
            if (qj - peak) * d > 0.0:
                peak = qj
        if (peak - q_now) * d > (q_now - q_end) * d or not q_end - q_end == peak - peak == 0.0:
            return None  # too early: the tip would stop short of the peak by more
        if (q_now - q_end) * d < TURN_MIN_DEG:
            return None  # a slow turn: the causal reversal's error is as small
        out = interp_linear(q_end, ys, b.knots)
        if (out - x_end) * d > 0.0:
            out = x_end
        return self._hold(hold, -d, out, t_b)

    def _hold(self, hold: PlanHold, d: int, out: float, until_s: float) -> float:
        """Command ``out`` until the model's knob, following the plan, catches up with it, at
        the latest ``until_s`` (+ 0.1 s) from now: a plan that turns again never leaves the
        knob held."""
        hold.direction = d
        hold.out_deg = out
        hold.until = self.index + round((until_s + _HOLD_MARGIN_S) / self.period_s)
        return out
