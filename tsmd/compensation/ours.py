"""Our compensator: the paper's play structure with the weaknesses the paper names removed.

1. Curved branches instead of straight lines. The loaded branch of each direction is a
   tabulated shape ``s(u)`` (tip = H + omega * s(u), u = knob angle past the dead-zone edge),
   identified from the motor current: once the tendon is engaged the current is proportional to
   the tendon tension, hence to the bending moment, hence to the tip angle; so the current's shape
   along the sweep is the tip's shape. The scale comes from the data sheet (the reference point).
   ``s(u) = max(u, 0)`` gives back the paper's lines exactly.
2. No jerk at transitions. The dead-zone edges are rounded by the same identified shapes, and the
   end of the backlash is a C1 blend (width ``backlash_blend_deg``) instead of a corner, so the
   inverse's command is continuous in slope wherever the model is.
3. Knob coupling. Each knob's parameters follow the other knob's *commanded* angle (where that
   knob really is), not its desired angle: the calibration grid is indexed by the knob angle, and
   with compensation the two differ by up to the dead zone plus the backlash.
4. Drive lag. The drive follows its target with a lag identified from commanded vs actual
   position; the compensator inverts the model at the desired angle predicted ``lag_s`` ahead.

All of it is identified from the calibration sweeps alone (commanded and actual knob position,
motor current, data-sheet constants): :func:`fit_ours_knob`.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.compensation.grid import ParameterField

SHAPE_U_DEG: tuple[float, ...] = tuple(float(u) for u in range(-20, 125, 5))
"""Default knob-angle offsets from the dead-zone edge at which the branch shapes are sampled."""

_TABLE_X_DEG = np.linspace(-200.0, 200.0, 801)
_FLAT_SLOPE = 1e-6  # makes the envelopes strictly increasing so that they can be inverted
_MAX_LEAD_DEG = 10.0


@dataclass(frozen=True)
class OursParams:
    """Our compensator's extra parameters for one knob (grids over the other knob's angle)."""

    lag_s: float
    backlash_blend_deg: tuple[float, ...]
    shape_u_deg: tuple[float, ...]
    shape_pos: tuple[tuple[float, ...], ...]  # (n_grid, n_u): s of the rising loaded branch
    shape_neg: tuple[tuple[float, ...], ...]  # (n_grid, n_u): s of the falling loaded branch

    @staticmethod
    def neutral(n_grid: int, u_deg: Sequence[float] = SHAPE_U_DEG) -> OursParams:
        """The parameters that make ours behave like the paper's lines (no lag, no blend)."""
        u = tuple(float(v) for v in u_deg)
        row = tuple(max(v, 0.0) for v in u)
        return OursParams(0.0, (0.0,) * n_grid, u, (row,) * n_grid, (row,) * n_grid)


def _row(values: Any, name: str, n: int, lo: float, hi: float) -> tuple[float, ...]:
    if isinstance(values, str) or not isinstance(values, Sequence):
        raise ValueError(f"{name}: must be a list of numbers")
    if len(values) != n:
        raise ValueError(f"{name}: must have {n} values, got {len(values)}")
    out = []
    for i, v in enumerate(values):
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise ValueError(f"{name}[{i}]: must be a number, got {v!r}")
        f = float(v)
        if math.isnan(f):
            raise ValueError(f"{name}[{i}]: is NaN")
        if not lo <= f <= hi:
            raise ValueError(f"{name}[{i}]: {f} is outside [{lo}, {hi}]")
        out.append(f)
    return tuple(out)


def ours_params_from_mapping(m: Mapping[str, Any], n_grid: int) -> OursParams:
    """Validate the ``ours`` block of a profile knob (ValueError naming the key)."""
    known = {"lag_s", "backlash_blend_deg", "shape_u_deg", "shape_pos", "shape_neg"}
    for key in m:
        if key not in known:
            raise ValueError(f"{key}: unknown key")
    for key in known:
        if key not in m:
            raise ValueError(f"{key}: missing key")
    lag = _row([m["lag_s"]], "lag_s", 1, 0.0, 1.0)[0]
    blend = _row(m["backlash_blend_deg"], "backlash_blend_deg", n_grid, 0.0, 45.0)
    u_raw = m["shape_u_deg"]
    u = _row(u_raw, "shape_u_deg", len(u_raw) if isinstance(u_raw, Sequence) else -1,
             -90.0, 270.0)
    if len(u) < 3 or any(b <= a for a, b in itertools.pairwise(u)):
        raise ValueError("shape_u_deg: must be at least 3 strictly increasing values")
    shapes = []
    for key in ("shape_pos", "shape_neg"):
        rows = m[key]
        if isinstance(rows, str) or not isinstance(rows, Sequence) or len(rows) != n_grid:
            raise ValueError(f"{key}: must be {n_grid} rows (one per grid point)")
        table = tuple(_row(r, f"{key}[{i}]", len(u), -10.0, 400.0) for i, r in enumerate(rows))
        for i, r in enumerate(table):
            if any(b < a for a, b in itertools.pairwise(r)):
                raise ValueError(f"{key}[{i}]: shape must be non-decreasing")
        shapes.append(table)
    return OursParams(lag, blend, u, shapes[0], shapes[1])


def ours_params_to_mapping(p: OursParams) -> dict[str, Any]:
    return {"lag_s": p.lag_s, "backlash_blend_deg": list(p.backlash_blend_deg),
            "shape_u_deg": list(p.shape_u_deg), "shape_pos": [list(r) for r in p.shape_pos],
            "shape_neg": [list(r) for r in p.shape_neg]}


# ----------------------------------------------------------------------------------------------
# The model


def smooth_max_excess(delta: float, w: float) -> float:
    """f(delta) with smax(a, b) = a + f(b - a): a C1 quadratic blend of max over width 2w."""
    if w <= 0.0 or delta >= w:
        return max(delta, 0.0)
    if delta <= -w:
        return 0.0
    return (delta + w) ** 2 / (4.0 * w)


def smooth_max_excess_inverse(z: float, w: float) -> float:
    """delta such that f(delta) = z, for z > 0."""
    if w <= 0.0 or z >= w:
        return z
    return 2.0 * math.sqrt(max(w * z, 0.0)) - w


@dataclass(frozen=True)
class Envelopes:
    """The rising and falling branches of one knob at one instant, tabulated for inversion."""

    x_deg: NDArray[np.float64]
    rising_deg: NDArray[np.float64]
    falling_deg: NDArray[np.float64]
    omega: float
    blend_tip_deg: float

    def rising(self, x: float) -> float:
        return float(np.interp(x, self.x_deg, self.rising_deg))

    def falling(self, x: float) -> float:
        return float(np.interp(x, self.x_deg, self.falling_deg))

    def rising_inverse(self, y: float) -> float:
        return _inverse(y, self.rising_deg, self.x_deg, self.omega)

    def falling_inverse(self, y: float) -> float:
        return _inverse(y, self.falling_deg, self.x_deg, self.omega)


def _inverse(y: float, ys: NDArray[np.float64], xs: NDArray[np.float64], omega: float) -> float:
    if y <= ys[0]:
        return float(xs[0] + (y - ys[0]) / omega)
    if y >= ys[-1]:
        return float(xs[-1] + (y - ys[-1]) / omega)
    return float(np.interp(y, ys, xs))


def _shape(u: NDArray[np.float64], u_grid: NDArray[np.float64],
           s: NDArray[np.float64]) -> NDArray[np.float64]:
    """s(u) from the table; 0 below it, continued with the last slope above it."""
    out = np.interp(u, u_grid, s, left=0.0)
    slope = (s[-1] - s[-2]) / (u_grid[-1] - u_grid[-2])
    above = u > u_grid[-1]
    out[above] = s[-1] + slope * (u[above] - u_grid[-1])
    return out


def envelopes(dead_zone_pos_deg: float, dead_zone_neg_deg: float, backlash_pos_deg: float,
              backlash_neg_deg: float, height_pos_deg: float, height_neg_deg: float,
              omega: float, u_deg: NDArray[np.float64], shape_pos: NDArray[np.float64],
              shape_neg: NDArray[np.float64], blend_deg: float) -> Envelopes:
    """Rising = H_pos + omega*(s_pos(x - D_pos) - s_neg(D_hat_pos - x)); falling likewise.

    With s(u) = max(u, 0) these are exactly the paper's L2/L3/L4 and L6/L7/L8 (Eq. D_hats).
    """
    d_hat_pos = (height_pos_deg - height_neg_deg) / omega + dead_zone_neg_deg + backlash_neg_deg
    d_hat_neg = (height_neg_deg - height_pos_deg) / omega + dead_zone_pos_deg - backlash_pos_deg
    x = _TABLE_X_DEG
    rising = height_pos_deg + omega * (_shape(x - dead_zone_pos_deg, u_deg, shape_pos)
                                       - _shape(d_hat_pos - x, u_deg, shape_neg))
    falling = height_neg_deg + omega * (_shape(x - d_hat_neg, u_deg, shape_pos)
                                        - _shape(dead_zone_neg_deg - x, u_deg, shape_neg))
    ramp = _FLAT_SLOPE * omega * x
    rising = np.maximum.accumulate(rising) + ramp
    falling = np.maximum.accumulate(falling) + ramp
    return Envelopes(x, rising, falling, omega, omega * blend_deg)


@dataclass(frozen=True)
class OursState:
    """Command x, model output y, direction, the output held at the last reversal and the blend
    width in force since then (never wider than the gap at the reversal: no jump)."""

    x_deg: float
    y_deg: float
    direction: int
    held_deg: float
    blend_tip_deg: float


def ours_model_step(state: OursState, x_deg: float, env: Envelopes) -> OursState:
    """Forward model: the smooth play. Used by tests and for the inverse's bookkeeping."""
    dx = x_deg - state.x_deg
    direction = state.direction if dx == 0 else (1 if dx > 0 else -1)
    held, blend = state.held_deg, state.blend_tip_deg
    if direction != state.direction:
        held = state.y_deg
        gap = (held - env.rising(state.x_deg)) if direction > 0 else (env.falling(state.x_deg)
                                                                      - held)
        blend = min(env.blend_tip_deg, max(gap, 0.0))
    if direction > 0:
        y = held + smooth_max_excess(env.rising(x_deg) - held, blend)
    else:
        y = held - smooth_max_excess(held - env.falling(x_deg), blend)
    return OursState(x_deg, y, direction, held, blend)


def ours_inverse_step(state: OursState, y_desired_deg: float, env: Envelopes) -> OursState:
    """The input that makes the smooth play output ``y_desired_deg``."""
    y = y_desired_deg
    if y == state.y_deg:
        return state
    direction = 1 if y > state.y_deg else -1
    held, blend = state.held_deg, state.blend_tip_deg
    if direction != state.direction:
        held = state.y_deg
        gap = (held - env.rising(state.x_deg)) if direction > 0 else (env.falling(state.x_deg)
                                                                      - held)
        blend = min(env.blend_tip_deg, max(gap, 0.0))
    if direction > 0:
        b = held + smooth_max_excess_inverse(y - held, blend)
        x = env.rising_inverse(b)
    else:
        b = held - smooth_max_excess_inverse(held - y, blend)
        x = env.falling_inverse(b)
    if (x - state.x_deg) * direction < 0:  # never move against the desired direction
        x = state.x_deg
    return OursState(x, y, direction, held, blend)


@dataclass(frozen=True)
class OursKnob:
    """One knob of our compensator: main and extra parameters over the other knob's angle."""

    field: ParameterField  # D_pos, D_neg, B_pos, B_neg, blend
    shape_pos: ParameterField
    shape_neg: ParameterField
    u_deg: NDArray[np.float64]
    height_pos_deg: float
    height_neg_deg: float
    omega: float
    lag_s: float

    def envelopes(self, other_deg: float) -> Envelopes:
        d_pos, d_neg, b_pos, b_neg, blend = self.field.at(other_deg)
        return envelopes(float(d_pos), float(d_neg), max(float(b_pos), 0.0),
                         max(float(b_neg), 0.0), self.height_pos_deg, self.height_neg_deg,
                         self.omega, self.u_deg, self.shape_pos.at(other_deg),
                         self.shape_neg.at(other_deg), max(float(blend), 0.0))


class OursCompensator:
    """Two knobs; each follows the other knob's commanded angle and leads by the drive lag."""

    def __init__(self, knobs: tuple[OursKnob, OursKnob], period_s: float) -> None:
        if not period_s > 0:
            raise ValueError(f"period_s must be positive, got {period_s}")
        self.knobs = knobs
        self.period_s = period_s
        self._states: list[OursState] = []
        self._q_prev = np.zeros(2)
        self._v_deg_s = np.zeros(2)
        self.reset(np.zeros(2))

    def reset(self, q_deg: NDArray[np.float64]) -> None:
        q = np.asarray(q_deg, dtype=float).copy()
        q[~np.isfinite(q)] = 0.0
        self._q_prev = q.copy()
        self._v_deg_s = np.zeros(2)
        states = []
        for i, knob in enumerate(self.knobs):
            env = knob.envelopes(float(q[1 - i]))
            lo, hi = env.falling_inverse(q[i]), env.rising_inverse(q[i])
            if lo <= 0.0 <= hi:
                x, d = 0.0, 1
            else:
                x, d = (lo, -1) if hi < 0.0 else (hi, 1)
            states.append(OursState(x, float(q[i]), d, float(q[i]), 0.0))
        self._states = states

    def command(self, q_deg: NDArray[np.float64]) -> NDArray[np.float64]:
        q = np.asarray(q_deg, dtype=float)
        ok = np.isfinite(q)
        # velocity of the desired trajectory, lightly filtered, for the lag lead
        v = np.where(ok, (np.where(ok, q, self._q_prev) - self._q_prev) / self.period_s, 0.0)
        self._v_deg_s = 0.7 * self._v_deg_s + 0.3 * v
        target = q.copy()
        for i, knob in enumerate(self.knobs):
            lead = float(np.clip(knob.lag_s * self._v_deg_s[i], -_MAX_LEAD_DEG, _MAX_LEAD_DEG))
            target[i] = q[i] + lead
        other = np.array([s.x_deg for s in self._states])
        out = np.empty(2)
        for i, knob in enumerate(self.knobs):
            state = self._states[i]
            if ok[i]:
                env = knob.envelopes(float(other[1 - i]))
                state = ours_inverse_step(state, float(target[i]), env)
                self._states[i] = state
            out[i] = state.x_deg
        self._q_prev = np.where(ok, q, self._q_prev)
        return out


# ----------------------------------------------------------------------------------------------
# Identification (called by the calibration with the arrays it collects)


@dataclass(frozen=True)
class SweepData:
    """One calibration sweep of one knob with the other knob held at ``other_knob_deg``.

    Arrays of equal length, uncompensated: ``cmd_deg`` commanded and ``pos_deg`` actual knob
    angle, ``current_A`` the knob motor's current (filtered or raw: it is filtered again here).
    ``dead_zone_*``/``backlash_*`` are what the paper's identification found for this sweep.
    """

    t_s: NDArray[np.float64]
    cmd_deg: NDArray[np.float64]
    pos_deg: NDArray[np.float64]
    current_A: NDArray[np.float64]
    other_knob_deg: float
    dead_zone_pos_deg: float
    dead_zone_neg_deg: float
    backlash_pos_deg: float
    backlash_neg_deg: float


def estimate_lag_s(t_s: NDArray[np.float64], cmd_deg: NDArray[np.float64],
                   pos_deg: NDArray[np.float64], max_lag_s: float = 0.5) -> float:
    """The delay that best maps commanded onto actual position (least squares over a grid)."""
    t = np.asarray(t_s, float)
    cmd = np.asarray(cmd_deg, float)
    pos = np.asarray(pos_deg, float)
    ok = np.isfinite(t) & np.isfinite(cmd) & np.isfinite(pos)
    t, cmd, pos = t[ok], cmd[ok], pos[ok]
    if t.size < 10:
        return 0.0
    dt = float(np.median(np.diff(t)))
    lags = np.arange(0.0, max_lag_s + 0.5 * dt, max(dt / 4.0, 1e-4))
    errors = [float(np.mean((np.interp(t - lag, t, cmd) - pos)[t > t[0] + max_lag_s] ** 2))
              for lag in lags]
    return float(lags[int(np.argmin(errors))])
