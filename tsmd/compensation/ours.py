"""Our compensator: the paper's play structure, addressing the weaknesses the paper names.

1. Straight lines where the catheter is not. Friction along the sheath makes the backlash grow
   with the load at the reversal (a reversal at 60 deg tip loses less knob travel than one at
   90 deg): the released tendon's branch is steeper than the loaded one. The paper draws the
   release branch parallel to the loaded one, shifted by the backlash measured at the calibration
   amplitude, so every smaller reversal is over-compensated. Here each release branch is a line
   of its own slope through the end of the backlash after the reversal at the reference point
   (``release_omega``, ``reference_backlash_*_deg``: data-sheet constants measured once per
   product, like omega and the reference points), moving with the catheter's dead-zone edge D
   (from its current) over the other knob's angle. Without those constants it goes through the
   end of the backlash the current showed at the calibration amplitude and the tendon's slack
   point (:func:`release_line`, :func:`fit_ours_knob`).
2. Transitions. The dead-zone edge the current shows is moved to where the tip leaves its
   plateau (``dead_zone_offset_deg``, data sheet). Dead-zone jumps are started early so that the
   motor's crossing time is centred on the desired crossing; the command is limited and
   averaged over 0.1 s, which bounds its jerk to 2 a_max / 0.1 s (:class:`OursCompensator`);
   smaller reversals make smaller backlash jumps; the backlash end can be a C1 blend
   (``backlash_blend_deg``).
3. Knob coupling. Each knob's parameters follow the grid coordinate at which calibration saw
   the other tip where it is now wanted: the other knob's loaded-branch angle for the other
   tip's desired angle (the paper uses the other knob's desired angle, up to D + B off).
4. Drive lag. The drive follows its target with a lag identified from commanded vs actual
   position; the compensator inverts the model at the desired angle predicted ``lag_s`` ahead.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.compensation.grid import ParameterField
from tsmd.compensation.safety import (
    DEFAULT_MAX_ACCEL_DEG_S2,
    DEFAULT_MAX_VELOCITY_DEG_S,
    KnobLimits,
    LimiterState,
    limit_step,
)

_TABLE_X_DEG = np.linspace(-200.0, 200.0, 1601)
_FLAT_SLOPE = 1e-6  # makes the envelopes strictly increasing so that they can be inverted
_MAX_LEAD_DEG = 10.0
RELEASE_SLOPE_RANGE: tuple[float, float] = (0.2, 10.0)


@dataclass(frozen=True)
class OursParams:
    """Our compensator's extra parameters for one knob (grids over the other knob's angle).

    The release line of the positive side (moving down above the dead zone, the tendon pulled by
    positive rotation letting go) has slope ``release_slope_pos`` and meets the falling plateau
    H_neg at knob angle ``release_pivot_pos_deg``; likewise ``*_neg`` below the dead zone.
    ``backlash_blend_deg``: half-width of the C1 blend at the end of the backlash (0 = corner).
    ``lag_s``: delay of the drive's actual position behind its target.
    ``dead_zone_offset_deg``: added outward to the current's dead-zone edges (data sheet).
    """

    lag_s: float
    release_slope_pos: tuple[float, ...]
    release_slope_neg: tuple[float, ...]
    release_pivot_pos_deg: tuple[float, ...]
    release_pivot_neg_deg: tuple[float, ...]
    backlash_blend_deg: tuple[float, ...]
    dead_zone_offset_deg: float = 0.0
    """Where the tip leaves the plateau beyond the edge the current shows (data sheet)."""

    @staticmethod
    def pivot_at_dead_zone(omega: float, dead_zone_pos_deg: Sequence[float],
                           dead_zone_neg_deg: Sequence[float]) -> OursParams:
        """Release lines parallel to the loaded ones from the dead-zone edges, no blend/lag."""
        n = len(dead_zone_pos_deg)
        return OursParams(0.0, (omega,) * n, (omega,) * n,
                          tuple(float(v) for v in dead_zone_pos_deg),
                          tuple(float(v) for v in dead_zone_neg_deg), (0.0,) * n)


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


_OURS_KEYS = ("lag_s", "release_slope_pos", "release_slope_neg", "release_pivot_pos_deg",
              "release_pivot_neg_deg", "backlash_blend_deg")


def ours_params_from_mapping(m: Mapping[str, Any], n_grid: int) -> OursParams:
    """Validate the ``ours`` block of a profile knob (ValueError naming the key)."""
    for key in m:
        if key not in (*_OURS_KEYS, "dead_zone_offset_deg"):
            raise ValueError(f"{key}: unknown key")
    for key in _OURS_KEYS:
        if key not in m:
            raise ValueError(f"{key}: missing key")
    lag = _row([m["lag_s"]], "lag_s", 1, 0.0, 1.0)[0]
    lo, hi = RELEASE_SLOPE_RANGE
    return OursParams(lag,
                      _row(m["release_slope_pos"], "release_slope_pos", n_grid, lo, hi),
                      _row(m["release_slope_neg"], "release_slope_neg", n_grid, lo, hi),
                      _row(m["release_pivot_pos_deg"], "release_pivot_pos_deg", n_grid, -90, 180),
                      _row(m["release_pivot_neg_deg"], "release_pivot_neg_deg", n_grid, -180, 90),
                      _row(m["backlash_blend_deg"], "backlash_blend_deg", n_grid, 0.0, 45.0),
                      _row([m.get("dead_zone_offset_deg", 0.0)], "dead_zone_offset_deg", 1,
                           -20.0, 20.0)[0])


def ours_params_to_mapping(p: OursParams) -> dict[str, Any]:
    return {"lag_s": p.lag_s, "release_slope_pos": list(p.release_slope_pos),
            "release_slope_neg": list(p.release_slope_neg),
            "release_pivot_pos_deg": list(p.release_pivot_pos_deg),
            "release_pivot_neg_deg": list(p.release_pivot_neg_deg),
            "backlash_blend_deg": list(p.backlash_blend_deg),
            "dead_zone_offset_deg": p.dead_zone_offset_deg}


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


def envelopes(dead_zone_pos_deg: float, dead_zone_neg_deg: float, height_pos_deg: float,
              height_neg_deg: float, omega: float, release_slope_pos: float,
              release_slope_neg: float, release_pivot_pos_deg: float,
              release_pivot_neg_deg: float, blend_deg: float) -> Envelopes:
    """The rising and falling branches, with release lines of their own.

    Loaded parts as in the paper: slope omega from the dead-zone edges D at heights H. Release
    parts: the line of ``release_slope_*`` that meets the other plateau at ``release_pivot_*``
    (:func:`release_line`). Because the release line is steeper than the loaded one, the
    backlash grows with the load at the reversal, as friction along the sheath makes it do.
    """
    x = _TABLE_X_DEG
    rising = (height_pos_deg + omega * np.maximum(x - dead_zone_pos_deg, 0.0)
              + release_slope_neg * np.minimum(x - release_pivot_neg_deg, 0.0))
    falling = (height_neg_deg + release_slope_pos * np.maximum(x - release_pivot_pos_deg, 0.0)
               + omega * np.minimum(x - dead_zone_neg_deg, 0.0))
    lower = np.minimum(rising, falling) + _FLAT_SLOPE * omega * x
    upper = np.maximum(rising, falling) + _FLAT_SLOPE * omega * x
    return Envelopes(x, lower, upper, omega, omega * blend_deg)


def release_line(amplitude_deg: float, dead_zone_deg: float, backlash_deg: float,
                 height_loaded_deg: float, height_released_deg: float, omega: float
                 ) -> tuple[float, float]:
    """(slope, pivot) of one side's release line from a calibration sweep alone.

    A sweep to ``amplitude_deg`` ends on the loaded line at H + omega*(A - D); after the reversal
    the tip holds for the backlash B, so the release line passes through (A -/+ B, that height).
    The tendon is taken to go slack where it engaged (pivot = D), which fixes the slope. For the
    negative side pass the negative amplitude, D_neg, B_neg, H_neg as loaded and H_pos as
    released height.
    """
    sign = 1.0 if amplitude_deg > 0 else -1.0
    lo, hi = RELEASE_SLOPE_RANGE
    y_end = height_loaded_deg + omega * (amplitude_deg - dead_zone_deg)
    x_end = amplitude_deg - sign * backlash_deg
    run = x_end - dead_zone_deg
    if sign * run <= 1.0:
        return omega, float(dead_zone_deg)
    s = float(min(max((y_end - height_released_deg) / run, lo), hi))
    return s, float(x_end - (y_end - height_released_deg) / s)


def release_line_from_reference(knob_deg: float, tip_deg: float, height_released_deg: float,
                                slope: float, shift_deg: float = 0.0) -> tuple[float, float]:
    """(slope, pivot) of a release line from the data sheet: it passes through the end of the
    backlash after the reversal at the reference point, ``(X_ref -/+ B_ref, Y_ref)``, with the
    data sheet's release slope, and moves with the dead-zone edge by ``shift_deg`` (the change of
    D with the other knob's angle, from the current), like the loaded line does."""
    lo, hi = RELEASE_SLOPE_RANGE
    s = float(min(max(slope, lo), hi))
    return s, float(knob_deg - (tip_deg - height_released_deg) / s + shift_deg)


@dataclass(frozen=True)
class OursState:
    """Command x, model output y, direction, the output held at the last reversal and the blend
    width in force since then (never wider than the gap at the reversal: no jump)."""

    x_deg: float
    y_deg: float
    direction: int
    held_deg: float
    blend_tip_deg: float


def _held_and_blend(state: OursState, direction: int, env: Envelopes) -> tuple[float, float]:
    """The held output and transition blend; a reversal holds the output where it is."""
    if direction == state.direction:
        return state.held_deg, state.blend_tip_deg
    held = state.y_deg
    gap = (held - env.rising(state.x_deg)) if direction > 0 else (env.falling(state.x_deg) - held)
    return held, min(env.blend_tip_deg, max(gap, 0.0))


def ours_model_step(state: OursState, x_deg: float, env: Envelopes) -> OursState:
    """Forward model: the smooth play. Used by tests and for the inverse's bookkeeping."""
    dx = x_deg - state.x_deg
    direction = state.direction if dx == 0 else (1 if dx > 0 else -1)
    held, blend = _held_and_blend(state, direction, env)
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
    held, blend = _held_and_blend(state, direction, env)
    if direction > 0:
        b = held + smooth_max_excess_inverse(y - held, blend)
        x = env.rising_inverse(b)
    else:
        b = held - smooth_max_excess_inverse(held - y, blend)
        x = env.falling_inverse(b)
    if (x - state.x_deg) * direction < 0:  # never move against the desired direction
        x = state.x_deg
    return OursState(x, y, direction, held, blend)


OURS_COLUMNS: tuple[str, ...] = (
    "dead_zone_pos_deg", "dead_zone_neg_deg", "release_slope_pos", "release_slope_neg",
    "release_pivot_pos_deg", "release_pivot_neg_deg", "backlash_blend_deg")
"""The parameters of :attr:`OursKnob.field`, in the column order :meth:`OursKnob.envelopes`
reads them."""


def ours_field(other_knob_deg: Sequence[float], dead_zone_pos_deg: Sequence[float],
               dead_zone_neg_deg: Sequence[float], params: OursParams,
               interpolation: str = "pchip") -> ParameterField:
    """The named field of one knob: the (offset) dead-zone edges and our extra parameters."""
    return ParameterField.from_columns(other_knob_deg, {
        "dead_zone_pos_deg": dead_zone_pos_deg,
        "dead_zone_neg_deg": dead_zone_neg_deg,
        "release_slope_pos": params.release_slope_pos,
        "release_slope_neg": params.release_slope_neg,
        "release_pivot_pos_deg": params.release_pivot_pos_deg,
        "release_pivot_neg_deg": params.release_pivot_neg_deg,
        "backlash_blend_deg": params.backlash_blend_deg,
    }, interpolation)


@dataclass(frozen=True)
class OursKnob:
    """One knob of our compensator: parameters over the other knob's angle + constants."""

    field: ParameterField  # named :data:`OURS_COLUMNS`, built by :func:`ours_field`
    height_pos_deg: float
    height_neg_deg: float
    omega: float
    lag_s: float

    def __post_init__(self) -> None:
        if self.field.columns != OURS_COLUMNS:
            raise ValueError(f"our compensator's field must hold {OURS_COLUMNS}, "
                             f"got {self.field.columns}")

    def envelopes(self, other_deg: float) -> Envelopes:
        d_pos, d_neg, s_pos, s_neg, p_pos, p_neg, blend = (float(v) for v in
                                                            self.field.at(other_deg))
        return envelopes(d_pos, d_neg, self.height_pos_deg, self.height_neg_deg, self.omega,
                         s_pos, s_neg, p_pos, p_neg, max(blend, 0.0))

    def loaded_knob_deg(self, tip_deg: float, other_deg: float) -> float:
        """The knob angle that gives ``tip_deg`` on a loaded branch (how calibration held it)."""
        d_pos, d_neg = (float(v) for v in self.field.at(other_deg)[:2])
        h_hi = max(self.height_pos_deg, self.height_neg_deg)
        h_lo = min(self.height_pos_deg, self.height_neg_deg)
        if tip_deg >= h_hi:
            return d_pos + (tip_deg - h_hi) / self.omega
        if tip_deg <= h_lo:
            return d_neg + (tip_deg - h_lo) / self.omega
        # on the plateau the knob can be anywhere in the dead zone: interpolate, stay continuous
        return d_neg + (d_pos - d_neg) * (tip_deg - h_lo) / (h_hi - h_lo)


class OursCompensator:
    """Two knobs. Each knob's parameters follow where the other knob would sit on its loaded
    branch for the other tip's desired angle (the coupling acts through the bent section, and
    calibration held the other knob on its loaded branch); each leads by its drive's lag.

    Jumps across the dead zone are centred: the motor needs about
    ``W / max_velocity + max_velocity / max_accel`` to cross a dead zone of width W, during
    which the tip stays on the plateau whatever is commanded. The paper starts the crossing when
    the desired angle reaches the plateau, so the whole crossing time is lag. Ours looks ahead
    half the crossing time along the desired velocity and, if a jump lies there, starts it; the
    command then holds (never steps back, which would be a reversal) until the desired angle
    catches up.
    """

    def __init__(self, knobs: tuple[OursKnob, OursKnob], period_s: float,
                 max_velocity_deg_s: float = DEFAULT_MAX_VELOCITY_DEG_S,
                 max_accel_deg_s2: float = DEFAULT_MAX_ACCEL_DEG_S2,
                 smoothing_s: float = 0.1) -> None:
        if not period_s > 0:
            raise ValueError(f"period_s must be positive, got {period_s}")
        if not (max_velocity_deg_s > 0 and max_accel_deg_s2 > 0):
            raise ValueError("max_velocity_deg_s and max_accel_deg_s2 must be positive")
        self.knobs = knobs
        self.period_s = period_s
        self.max_velocity_deg_s = max_velocity_deg_s
        self.max_accel_deg_s2 = max_accel_deg_s2
        # Jerk: the command goes through the velocity/acceleration limits and then a moving
        # average over ``smoothing_s``; the average of a feasible motion stays feasible and its
        # acceleration can change by at most 2 a_max per window (jerk <= 2 a_max / smoothing_s).
        # Its delay (half the window) is taken out by inverting that much further ahead.
        self._n_avg = max(1, round(smoothing_s / period_s))
        self._free = KnobLimits(-1e9, 1e9, max_velocity_deg_s, max_accel_deg_s2)
        self._lim = [LimiterState(0.0), LimiterState(0.0)]
        self._window = np.zeros((2, self._n_avg))
        self._states: list[OursState] = []
        self._q_prev = np.zeros(2)
        self._v_deg_s = np.zeros(2)
        self._axis = np.zeros(2)  # grid coordinate of each knob as seen by the other
        self._out = np.zeros(2)  # the inverse's command (before limiting and smoothing)
        self._target = np.zeros(2)  # desired angle plus lead, as inverted last
        self._hold = [0, 0]  # direction of a jump started early, 0 = none
        self._cache: list[tuple[float, Envelopes] | None] = [None, None]
        self.reset(np.zeros(2))

    def replace_knobs(self, knobs: tuple[OursKnob, OursKnob]) -> None:
        """New parameters from now on, state kept (online re-estimation, tsmd.online)."""
        self.knobs = knobs
        self._cache = [None, None]

    def _envelopes(self, i: int) -> Envelopes:
        """Envelopes of knob i at the other knob's grid coordinate (cached while it is still)."""
        key = round(float(self._axis[1 - i]), 3)
        cached = self._cache[i]
        if cached is None or cached[0] != key:
            cached = (key, self.knobs[i].envelopes(key))
            self._cache[i] = cached
        return cached[1]

    def _update_axis(self, q: NDArray[np.float64]) -> None:
        axis = self._axis.copy()
        for i, knob in enumerate(self.knobs):
            if math.isfinite(q[i]):
                axis[i] = knob.loaded_knob_deg(float(q[i]), float(self._axis[1 - i]))
        self._axis = axis

    def reset(self, q_deg: NDArray[np.float64]) -> None:
        q = np.asarray(q_deg, dtype=float).copy()
        q[~np.isfinite(q)] = 0.0
        self._q_prev = q.copy()
        self._v_deg_s = np.zeros(2)
        self._axis = np.zeros(2)
        self._hold = [0, 0]
        for _ in range(3):  # settle the mutual dependence
            self._update_axis(q)
        states = []
        for i in range(2):
            env = self._envelopes(i)
            lo, hi = env.falling_inverse(q[i]), env.rising_inverse(q[i])
            if lo <= 0.0 <= hi:
                x, d = 0.0, 1
            else:
                x, d = (lo, -1) if hi < 0.0 else (hi, 1)
            states.append(OursState(x, float(q[i]), d, float(q[i]), 0.0))
        self._states = states
        self._target = q.copy()
        self._out = np.array([st.x_deg for st in states])
        self._lim = [LimiterState(float(x)) for x in self._out]
        self._window = np.repeat(self._out[:, None], self._n_avg, axis=1)

    def command(self, q_deg: NDArray[np.float64]) -> NDArray[np.float64]:
        q = np.asarray(q_deg, dtype=float)
        ok = np.isfinite(q)
        q_ok = np.where(ok, q, self._q_prev)
        # velocity of the desired trajectory, lightly filtered, for the lag lead
        self._v_deg_s = 0.7 * self._v_deg_s + 0.3 * (q_ok - self._q_prev) / self.period_s
        self._update_axis(q_ok)
        for i, knob in enumerate(self.knobs):
            if not ok[i]:
                continue  # hold the last command
            v = float(self._v_deg_s[i])
            ahead_s = knob.lag_s + 0.5 * (self._n_avg - 1) * self.period_s
            lead = float(np.clip(ahead_s * v, -_MAX_LEAD_DEG, _MAX_LEAD_DEG))
            target = float(q[i]) + lead
            # The lead shrinks when the desired angle slows down; it must never turn the
            # target back while the desired angle does not turn back itself: a false reversal
            # would make the inverse jump across the backlash.
            dq = float(q[i] - self._q_prev[i])
            back = (target - float(self._target[i])) * (dq if dq != 0.0 else 0.0)
            if back < 0.0 or (dq == 0.0 and (target - float(self._target[i]))
                              * self._states[i].direction < 0.0):
                target = float(self._target[i])
            self._target[i] = target
            env = self._envelopes(i)
            state = ours_inverse_step(self._states[i], target, env)
            self._states[i] = state
            self._out[i] = self._centred(i, state, target, v, env)
            self._lim[i] = limit_step(self._lim[i], float(self._out[i]), self._free,
                                      self.period_s)
            self._window[i] = np.roll(self._window[i], 1)
            self._window[i, 0] = self._lim[i].q_deg
        self._q_prev = q_ok
        smoothed: NDArray[np.float64] = self._window.mean(axis=1)
        return smoothed

    def _centred(self, i: int, state: OursState, target: float, v: float,
                 env: Envelopes) -> float:
        x = state.x_deg
        d = state.direction
        prev = float(self._out[i])
        if self._hold[i] != 0:
            if self._hold[i] == d and (x - prev) * d < 0:
                return prev  # the desired angle has not caught up with the early jump yet
            self._hold[i] = 0
        speed = abs(v)
        if speed < 1e-3 or np.sign(v) != d:
            return x
        # Look as far ahead as half the crossing time of a wide (60 deg) jump; if a jump is
        # there, look again at half the crossing time of that jump and start it when inside.
        horizon_s = 0.5 * 60.0 / self.max_velocity_deg_s
        for _ in range(2):
            ahead = ours_inverse_step(state, target + v * horizon_s, env).x_deg
            expected = speed * horizon_s / env.omega
            jump = (ahead - x) * d - expected
            if jump <= expected + 3.0:
                return x  # no jump within the horizon
            horizon_s = 0.5 * (jump / self.max_velocity_deg_s
                               + self.max_velocity_deg_s / self.max_accel_deg_s2)
        self._hold[i] = d
        return ahead


# ----------------------------------------------------------------------------------------------
# Identification (called by the calibration with the arrays it collects)
