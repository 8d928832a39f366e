"""Tension play: a play whose backlash grows with the tendon tension at the reversal.

Physics (capstan friction along an elastic tendon): after a reversal the sheath holds the distal
tension while the tendon's stretch is given back, so the knob travels a backlash proportional to
the tension it was pulling with, and the tendon's motor current is that tension. On the loaded
branch the current rises linearly from its zero-load point ``x0`` to the calibration amplitude
``A``, where the current also shows the backlash ``B_A``. Hence the backlash after a reversal at
``x_r`` is ``beta (x_r - x0)`` with ``beta = B_A / (A - x0)``, and the ends of all backlashes lie
on one release line of slope ``omega / (1 - beta)``, steeper than the loaded one: the paper's
fixed backlash and parallel release line are the special case ``x0 -> -inf``. Every catheter-
specific number (dead-zone edges, ``beta``, ``x0``, per other-knob angle) comes from that
catheter's calibration current (:mod:`tsmd.calibration.tension_play_fit`); ``omega`` and the
reference points that give the plateau heights are the data sheet's, as in the paper.

Per knob the rising branch (moving up) is the lower envelope and the falling branch the upper
envelope of the loaded lines, the plateaus and the two release lines; between them the output
is held (play). The inverse is exact on every sloped part and jumps across flat parts; the
command stage then starts dead-zone jumps early, limits velocity and acceleration and averages
over ``smoothing_s`` (jerk <= 2 a_max / smoothing_s), see :class:`TensionPlayCompensator`.
"""

from __future__ import annotations

import itertools
import math
from bisect import bisect_right
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.compensation.grid import ParameterField
from tsmd.compensation.safety import KnobLimits, LimiterState, limit_step

BETA_RANGE: tuple[float, float] = (0.0, 0.8)
"""Backlash per knob degree of load: 0 = no backlash; 0.8 = release slope 5 omega."""
_FLAT_SLOPE = 1e-6  # makes the envelopes strictly increasing so that they can be inverted
_FAR_DEG = 1000.0
_TABLE_STEP_DEG = 0.25  # resolution of the other knob's angle in the precomputed envelopes
_MAX_LEAD_DEG = 10.0
_JUMP_MIN_DEG = 3.0
REVERSAL_DEADBAND_DEG = 0.1
"""A desired angle that turns back by less than this is held: an exact inverse would make the
motor cross the whole backlash for every jitter of the operator's input (error <= this)."""


@dataclass(frozen=True)
class TensionPlayParams:
    """One knob's tension-play parameters; tuples are sampled on ``other_knob_deg``.

    ``dead_zone_*_deg``: where the tip leaves its plateau (current edge + data-sheet offset).
    ``backlash_gain_*``: beta, knob degrees of backlash per knob degree of load at the reversal.
    ``zero_load_*_deg``: where the loaded current ramp extrapolates to zero (the tension's zero).
    ``height_*_deg``: plateau heights from the data sheet's reference points (paper, H).
    ``lag_s``: delay of the drive's actual position behind its command.
    """

    omega: float
    height_pos_deg: float
    height_neg_deg: float
    other_knob_deg: tuple[float, ...]
    dead_zone_pos_deg: tuple[float, ...]
    dead_zone_neg_deg: tuple[float, ...]
    backlash_gain_pos: tuple[float, ...]
    backlash_gain_neg: tuple[float, ...]
    zero_load_pos_deg: tuple[float, ...]
    zero_load_neg_deg: tuple[float, ...]
    lag_s: float = 0.0

    def columns(self) -> NDArray[np.float64]:
        """(n, 6): D_pos, D_neg, beta_pos, beta_neg, x0_pos, x0_neg per grid point."""
        return np.column_stack([self.dead_zone_pos_deg, self.dead_zone_neg_deg,
                                self.backlash_gain_pos, self.backlash_gain_neg,
                                self.zero_load_pos_deg, self.zero_load_neg_deg]).astype(float)


_ROWS: dict[str, tuple[float, float]] = {
    "dead_zone_pos_deg": (0.0, 90.0), "dead_zone_neg_deg": (-90.0, 0.0),
    "backlash_gain_pos": BETA_RANGE, "backlash_gain_neg": BETA_RANGE,
    "zero_load_pos_deg": (-90.0, 90.0), "zero_load_neg_deg": (-90.0, 90.0),
}
_SCALARS: dict[str, tuple[float, float]] = {
    "omega": (0.2, 5.0), "height_pos_deg": (-90.0, 90.0), "height_neg_deg": (-90.0, 90.0),
    "lag_s": (0.0, 1.0),
}


def _number(value: Any, name: str, lo: float, hi: float) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{name}: must be a number, got {value!r}")
    f = float(value)
    if not math.isfinite(f):
        raise ValueError(f"{name}: is not finite")
    if not lo <= f <= hi:
        raise ValueError(f"{name}: {f} is outside [{lo}, {hi}]")
    return f


def _numbers(values: Any, name: str, n: int | None, lo: float, hi: float) -> tuple[float, ...]:
    if isinstance(values, str) or not isinstance(values, Sequence):
        raise ValueError(f"{name}: must be a list of numbers")
    if n is not None and len(values) != n:
        raise ValueError(f"{name}: must have {n} values, got {len(values)}")
    return tuple(_number(v, f"{name}[{i}]", lo, hi) for i, v in enumerate(values))


def tension_play_from_mapping(m: Mapping[str, Any]) -> TensionPlayParams:
    """Validate a profile's ``tension_play`` block (ValueError naming the key)."""
    known = {"other_knob_deg", *_ROWS, *_SCALARS}
    for key in m:
        if key not in known:
            raise ValueError(f"{key}: unknown key")
    for key in known - {"lag_s"}:
        if key not in m:
            raise ValueError(f"{key}: missing key")
    grid = _numbers(m["other_knob_deg"], "other_knob_deg", None, -180.0, 180.0)
    if len(grid) < 2 or any(b <= a for a, b in itertools.pairwise(grid)):
        raise ValueError("other_knob_deg: needs >= 2 strictly increasing values")
    s = {k: _number(m.get(k, 0.0), k, *r) for k, r in _SCALARS.items()}
    r = {k: _numbers(m[k], k, len(grid), *lim) for k, lim in _ROWS.items()}
    return TensionPlayParams(
        s["omega"], s["height_pos_deg"], s["height_neg_deg"], grid, r["dead_zone_pos_deg"],
        r["dead_zone_neg_deg"], r["backlash_gain_pos"], r["backlash_gain_neg"],
        r["zero_load_pos_deg"], r["zero_load_neg_deg"], s["lag_s"])


def tension_play_to_mapping(p: TensionPlayParams) -> dict[str, Any]:
    out: dict[str, Any] = {k: float(getattr(p, k)) for k in _SCALARS}
    out["other_knob_deg"] = list(p.other_knob_deg)
    out.update({k: list(getattr(p, k)) for k in _ROWS})
    return out


# ----------------------------------------------------------------------------------------------
# The model at one other-knob angle


@dataclass(frozen=True)
class Branches:
    """Rising (lower) and falling (upper) branch of one knob, piecewise linear on ``knots``."""

    knots: tuple[float, ...]
    rising_deg: tuple[float, ...]
    falling_deg: tuple[float, ...]

    def rising(self, x_deg: float) -> float:
        return _interp(x_deg, self.knots, self.rising_deg)

    def falling(self, x_deg: float) -> float:
        return _interp(x_deg, self.knots, self.falling_deg)

    def rising_inverse(self, y_deg: float) -> float:
        return _interp(y_deg, self.rising_deg, self.knots)

    def falling_inverse(self, y_deg: float) -> float:
        return _interp(y_deg, self.falling_deg, self.knots)


def _interp(x: float, xs: tuple[float, ...], ys: tuple[float, ...]) -> float:
    """Linear interpolation on strictly increasing ``xs``, extrapolating the end pieces."""
    i = min(max(bisect_right(xs, x) - 1, 0), len(xs) - 2)
    x0, x1 = xs[i], xs[i + 1]
    return ys[i] + (ys[i + 1] - ys[i]) * (x - x0) / (x1 - x0)


def release_line(omega: float, height_deg: float, dead_zone_deg: float, beta: float,
                 zero_load_deg: float) -> tuple[float, float]:
    """(slope, intercept) of the line through the ends of all backlashes of one side.

    A reversal at ``x_r`` on the loaded line ``y = H + omega (x_r - D)`` ends its backlash at
    ``x_r - beta (x_r - x0)`` (positive side; the formula is the same for the negative side):
    the ends lie on ``y = H + omega ((x - beta x0) / (1 - beta) - D)``.
    """
    b = min(max(beta, BETA_RANGE[0]), BETA_RANGE[1])
    slope = omega / (1.0 - b)
    return slope, height_deg - omega * dead_zone_deg - slope * b * zero_load_deg


def branches(p: TensionPlayParams, d_pos: float, d_neg: float, beta_pos: float,
             beta_neg: float, x0_pos: float, x0_neg: float) -> Branches:
    """The two branches from the loaded lines, plateaus and release lines.

    rising  = H_pos + omega max(x - D_pos, 0) + min(R_neg(x) - H_pos, 0)
    falling = H_neg + omega min(x - D_neg, 0) + max(R_pos(x) - H_neg, 0)
    then lower/upper envelope of the two (continuous and invertible for any parameters).
    """
    w, h_pos, h_neg = p.omega, p.height_pos_deg, p.height_neg_deg
    s_pos, c_pos = release_line(w, h_pos, d_pos, beta_pos, x0_pos)
    s_neg, c_neg = release_line(w, h_neg, d_neg, beta_neg, x0_neg)

    def rising(x: float) -> float:
        return h_pos + w * max(x - d_pos, 0.0) + min(s_neg * x + c_neg - h_pos, 0.0)

    def falling(x: float) -> float:
        return h_neg + w * min(x - d_neg, 0.0) + max(s_pos * x + c_pos - h_neg, 0.0)

    kinks = sorted({-_FAR_DEG, _FAR_DEG, d_pos, d_neg, (h_pos - c_neg) / s_neg,
                    (h_neg - c_pos) / s_pos})
    knots = [k for k in kinks if -_FAR_DEG <= k <= _FAR_DEG]
    # where the two cross, the envelopes have a kink too
    crossings = []
    for a, b in itertools.pairwise(knots):
        da, db = rising(a) - falling(a), rising(b) - falling(b)
        if da * db < 0.0:
            crossings.append(a + (b - a) * da / (da - db))
    xs = sorted(set(knots + crossings))
    xs = [x for i, x in enumerate(xs) if i == 0 or x - xs[i - 1] > 1e-9]
    lo, hi = [], []
    for x in xs:
        r, f = rising(x), falling(x)
        tilt = _FLAT_SLOPE * w * x
        lo.append(min(r, f) + tilt)
        hi.append(max(r, f) + tilt)
    return Branches(tuple(xs), tuple(lo), tuple(hi))


@dataclass(frozen=True)
class PlayState:
    """Command x, model output y, direction of motion, output held since the last reversal."""

    x_deg: float
    y_deg: float
    direction: int
    held_deg: float


def model_step(state: PlayState, x_deg: float, b: Branches) -> PlayState:
    """Forward model: the output for input ``x_deg`` (the play between the two branches)."""
    dx = x_deg - state.x_deg
    direction = state.direction if dx == 0.0 else (1 if dx > 0.0 else -1)
    held = state.held_deg if direction == state.direction else state.y_deg
    y = max(held, b.rising(x_deg)) if direction > 0 else min(held, b.falling(x_deg))
    return PlayState(x_deg, y, direction, held)


def inverse_step(state: PlayState, y_deg: float, b: Branches) -> PlayState:
    """The input that makes the model output ``y_deg`` next (exact on sloped parts).

    An unchanged output keeps a held input; one on a branch follows the branch forward if the
    branches moved (the other knob's angle changed the dead zone).
    """
    if not math.isfinite(y_deg):
        return state
    if y_deg == state.y_deg:
        if state.y_deg == state.held_deg:
            return state
        direction = state.direction
    else:
        direction = 1 if y_deg > state.y_deg else -1
    held = state.held_deg if direction == state.direction else state.y_deg
    if direction > 0:
        x = max(b.rising_inverse(y_deg), state.x_deg)
    else:
        x = min(b.falling_inverse(y_deg), state.x_deg)
    return PlayState(x, y_deg, direction, held)


def rest_state(y_deg: float, b: Branches, home_deg: float = 0.0) -> PlayState:
    """A knob brought to output ``y`` from ``home_deg`` and stopped (at start-up)."""
    lo, hi = b.falling_inverse(y_deg), b.rising_inverse(y_deg)
    if lo <= home_deg <= hi:
        return PlayState(home_deg, y_deg, 1, y_deg)
    if hi < home_deg:  # arrived moving down along the falling branch
        return PlayState(lo, y_deg, -1, max(y_deg, b.falling(home_deg)))
    return PlayState(hi, y_deg, 1, min(y_deg, b.rising(home_deg)))


class BranchTable:
    """One knob's branches precomputed over the other knob's angle (the grid interpolated)."""

    def __init__(self, p: TensionPlayParams, interpolation: str = "pchip") -> None:
        self.params = p
        field = ParameterField(p.other_knob_deg, p.columns(), interpolation)
        self._lo = float(p.other_knob_deg[0])
        n = max(2, round((p.other_knob_deg[-1] - self._lo) / _TABLE_STEP_DEG) + 1)
        self._step = (float(p.other_knob_deg[-1]) - self._lo) / (n - 1)
        self._table = [branches(p, *(float(v) for v in field.at(self._lo + i * self._step)))
                       for i in range(n)]

    def at(self, other_deg: float) -> Branches:
        """The branches at the other knob's angle (nearest table row, clamped to the grid)."""
        i = round((other_deg - self._lo) / self._step) if math.isfinite(other_deg) else 0
        return self._table[min(max(i, 0), len(self._table) - 1)]


# ----------------------------------------------------------------------------------------------
# The compensator: inverse, early jumps, limits, smoothing


class TensionPlayCompensator:
    """Two knobs of the tension play, as a :class:`tsmd.compensation.Compensator`.

    Each knob's branches follow the other knob's commanded angle (calibration held the other
    *knob* at each grid angle). Per tick and knob: the desired angle is led by the drive lag plus
    half the smoothing window; the inverse gives the command; a jump across a flat part seen
    within half the motor's crossing time ahead is started now and then held until the desired
    angle catches up (the crossing error is centred instead of all lag); the command then goes
    through the knob's position/velocity/acceleration limits and a moving average over
    ``smoothing_s``: the average of a feasible motion stays feasible, and its acceleration
    changes by at most 2 a_max per window, so the jerk is at most 2 a_max / ``smoothing_s``.
    """

    def __init__(self, knobs: tuple[TensionPlayParams, TensionPlayParams], period_s: float,
                 limits: Sequence[KnobLimits] | None = None, smoothing_s: float = 0.1,
                 interpolation: str = "pchip") -> None:
        if not period_s > 0:
            raise ValueError(f"period_s must be positive, got {period_s}")
        if limits is None:  # the simulated rig's drives, no position limit
            limits = (KnobLimits(-1e9, 1e9, 120.0, 2000.0),) * 2
        if len(limits) != 2:
            raise ValueError(f"need limits for 2 knobs, got {len(limits)}")
        self.params = knobs
        self.period_s = period_s
        self.limits = (limits[0], limits[1])
        # jumps are planned with the slower knob's limits
        self.v_max = min(lim.max_velocity_deg_s for lim in limits)
        self.a_max = min(lim.max_accel_deg_s2 for lim in limits)
        self._tables = (BranchTable(knobs[0], interpolation), BranchTable(knobs[1], interpolation))
        self._n_avg = max(1, round(smoothing_s / period_s))
        # faster than any knob can make the tip move (release slope <= 5 omega)
        self._jump_deg = 5.0 * max(k.omega for k in knobs) * self.v_max * period_s
        self._ahead_s = [k.lag_s + 0.5 * (self._n_avg - 1) * period_s for k in knobs]
        self._states = [PlayState(0.0, 0.0, 1, 0.0), PlayState(0.0, 0.0, 1, 0.0)]
        self._lim = [LimiterState(0.0), LimiterState(0.0)]
        self._window: list[list[float]] = [[0.0] * self._n_avg, [0.0] * self._n_avg]
        self._sum = [0.0, 0.0]
        self._slot = 0
        self._q_prev = [0.0, 0.0]
        self._v = [0.0, 0.0]
        self._target = [0.0, 0.0]
        self._out = [0.0, 0.0]
        self._hold = [0, 0]
        self._q_dir = [1, 1]
        self.reset(np.zeros(2))

    def reset(self, q_deg: NDArray[np.float64]) -> None:
        q = [float(v) if math.isfinite(v) else 0.0 for v in np.asarray(q_deg, dtype=float)]
        x = [0.0, 0.0]
        for _ in range(3):  # each knob's branches depend on the other knob's command
            self._states = [rest_state(q[i], self._tables[i].at(x[1 - i])) for i in (0, 1)]
            x = [s.x_deg for s in self._states]
        self._q_prev = list(q)
        self._v = [0.0, 0.0]
        self._target = list(q)
        self._out = list(x)
        self._hold = [0, 0]
        self._q_dir = [s.direction for s in self._states]
        x = [self.limits[i].clip(x[i]) for i in (0, 1)]
        self._lim = [LimiterState(x[0]), LimiterState(x[1])]
        self._window = [[x[0]] * self._n_avg, [x[1]] * self._n_avg]
        self._sum = [x[0] * self._n_avg, x[1] * self._n_avg]
        self._slot = 0

    def command(self, q_deg: NDArray[np.float64]) -> NDArray[np.float64]:
        q = (float(q_deg[0]), float(q_deg[1]))
        others = (self._states[1].x_deg, self._states[0].x_deg)
        slot = self._slot
        for i in (0, 1):
            qi = q[i]
            if math.isfinite(qi):
                self._track(i, qi, self._tables[i].at(others[i]))
            # non-finite desired angle: the command stays where it is (limited, smoothed)
            lim = limit_step(self._lim[i], self._out[i], self.limits[i], self.period_s)
            self._lim[i] = lim
            self._sum[i] += lim.q_deg - self._window[i][slot]
            self._window[i][slot] = lim.q_deg
        self._slot = (slot + 1) % self._n_avg
        n = self._n_avg
        return np.array([self._sum[0] / n, self._sum[1] / n])

    def _track(self, i: int, q_raw: float, b: Branches) -> None:
        qi = self._q_prev[i]
        if (q_raw - qi) * self._q_dir[i] >= 0.0:
            qi = q_raw
        elif abs(q_raw - qi) >= REVERSAL_DEADBAND_DEG:  # a reversal, not jitter
            qi = q_raw
            self._q_dir[i] = -self._q_dir[i]
        dq = qi - self._q_prev[i]
        self._q_prev[i] = qi
        v = 0.7 * self._v[i] + 0.3 * dq / self.period_s
        if abs(dq) > self._jump_deg:  # a step, not a motion: nothing to predict from it
            v = 0.0
        self._v[i] = v
        lead = min(max(self._ahead_s[i] * v, -_MAX_LEAD_DEG), _MAX_LEAD_DEG)
        target = qi + lead
        # The lead shrinks as the desired angle slows; it must never turn the target back while
        # the desired angle itself does not turn: a false reversal jumps across the backlash.
        step = target - self._target[i]
        state = self._states[i]
        if step * dq < 0.0 or (dq == 0.0 and step * state.direction < 0.0):
            target = self._target[i]

        self._target[i] = target
        state = inverse_step(state, target, b)
        self._states[i] = state
        self._out[i] = self._early_jump(i, state, target, v, b)

    def _early_jump(self, i: int, state: PlayState, target: float, v: float,
                    b: Branches) -> float:
        x, d = state.x_deg, state.direction
        prev = self._out[i]
        if self._hold[i] != 0:
            if self._hold[i] == d and (x - prev) * d < 0.0:
                return prev  # the desired angle has not caught up with the early jump yet
            self._hold[i] = 0
        speed = abs(v)
        if speed < 1e-3 or (v > 0) != (d > 0):
            return x
        horizon_s = 30.0 / self.v_max  # half the crossing time of a 60 deg jump
        ahead = x
        for _ in range(2):
            ahead = inverse_step(state, target + v * horizon_s, b).x_deg
            expected = speed * horizon_s / self.params[i].omega
            jump = (ahead - x) * d - expected
            if jump <= expected + _JUMP_MIN_DEG:
                return x
            horizon_s = 0.5 * (jump / self.v_max + self.v_max / self.a_max)
        self._hold[i] = d
        return ahead


def tension_play_compensator(knobs: Sequence[TensionPlayParams], period_s: float,
                             limits: Sequence[KnobLimits] | None = None,
                             interpolation: str = "pchip") -> TensionPlayCompensator:
    """The compensator for two knobs, within the knobs' limits (the sim rig's when None)."""
    return TensionPlayCompensator((knobs[0], knobs[1]), period_s, limits,
                                  interpolation=interpolation)
