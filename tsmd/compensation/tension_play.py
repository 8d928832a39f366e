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
is held (play). The inverse is exact on every sloped part and jumps across flat parts. The
compensator built on it (method ``ours``) is :class:`tsmd.compensation.ours.OursCompensator`.
"""

from __future__ import annotations

import itertools
from bisect import bisect_right
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import NamedTuple

from tsmd.compensation.release_round import (
    reversal_round_deg,
    rounded_drop_deg,
    rounded_gap_deg,
)
from tsmd.compensation.reversal_release import ReleaseEndShape, reversal_line
from tsmd.compensation.tension_play_params import BETA_RANGE

_FLAT_SLOPE = 1e-6  # makes the envelopes strictly increasing so that they can be inverted
_FAR_DEG = 1000.0


# ----------------------------------------------------------------------------------------------
# The model at one other-knob angle


class Flat(NamedTuple):
    """The widest flat part of a branch (the dead zone: both tendons slack, the tip stands at
    ``y_deg`` while the knob crosses ``lo_deg``..``hi_deg``)."""

    lo_deg: float
    hi_deg: float
    y_deg: float


FLAT_SLOPE_FRACTION = 0.05
"""A branch piece with a slope below this fraction of omega is flat (the envelopes' tilt is
1e-6 omega; the shallowest real piece is the loaded line, omega)."""


def widest_flat(knots: Sequence[float], ys: Sequence[float], omega: float) -> Flat | None:
    """The widest run of adjacent flat pieces of one branch, or None if it has none."""
    best: Flat | None = None
    lo = -1
    last = len(knots) - 2
    for i in range(last + 1):
        flat = ys[i + 1] - ys[i] < FLAT_SLOPE_FRACTION * omega * (knots[i + 1] - knots[i])
        if flat and lo < 0:
            lo = i
        if lo >= 0 and (not flat or i == last):
            hi = i + 1 if flat else i
            if best is None or knots[hi] - knots[lo] > best.hi_deg - best.lo_deg:
                best = Flat(knots[lo], knots[hi], 0.5 * (ys[lo] + ys[hi]))
            lo = -1
    return best


@dataclass(frozen=True)
class Branches:
    """Rising (lower) and falling (upper) branch of one knob, piecewise linear on ``knots``;
    ``round_pos_deg`` / ``round_neg_deg``: the rounded release's half-width (output deg) after
    a reversal from the positive / negative side (:mod:`tsmd.compensation.release_round`);
    ``release_end``: the product's release end per reversal (:mod:`tsmd.compensation.
    reversal_release`), None: the static release lines."""

    knots: tuple[float, ...]
    rising_deg: tuple[float, ...]
    falling_deg: tuple[float, ...]
    rising_flat: Flat | None = None
    falling_flat: Flat | None = None
    round_pos_deg: float = 0.0
    round_neg_deg: float = 0.0
    release_end: ReleaseEndShape | None = None

    def rising(self, x_deg: float) -> float:
        return interp_linear(x_deg, self.knots, self.rising_deg)

    def falling(self, x_deg: float) -> float:
        return interp_linear(x_deg, self.knots, self.falling_deg)

    def rising_inverse(self, y_deg: float) -> float:
        return interp_linear(y_deg, self.rising_deg, self.knots)

    def falling_inverse(self, y_deg: float) -> float:
        return interp_linear(y_deg, self.falling_deg, self.knots)


def interp_linear(x: float, xs: tuple[float, ...], ys: tuple[float, ...]) -> float:
    """Linear interpolation on strictly increasing ``xs``, extrapolating the end pieces (called
    every tick: plain comparisons, no builtins)."""
    i = bisect_right(xs, x) - 1
    if i < 0:
        i = 0
    elif i > len(xs) - 2:
        i = len(xs) - 2
    x0 = xs[i]
    y0 = ys[i]
    return y0 + (ys[i + 1] - y0) * (x - x0) / (xs[i + 1] - x0)


def release_line(omega: float, height_deg: float, dead_zone_deg: float, beta: float,
                 zero_load_deg: float) -> tuple[float, float]:
    """(slope, intercept) of the line through the ends of all backlashes of one side.

    A reversal at ``x_r`` on the loaded line ``y = H + omega (x_r - D)`` ends its backlash at
    ``x_r - beta (x_r - x0)`` (positive side; the formula is the same for the negative side):
    the ends lie on ``y = H + omega ((x - beta x0) / (1 - beta) - D)``.
    """
    b = min(max(beta, BETA_RANGE[0]), BETA_RANGE[1])
    slope = release_slope(omega, beta)
    return slope, height_deg - omega * dead_zone_deg - slope * b * zero_load_deg


def release_slope(omega: float, beta: float) -> float:
    """The release line's slope, tip per knob degree: ``omega / (1 - beta)``, beta clamped to
    :data:`BETA_RANGE`."""
    return omega / (1.0 - min(max(beta, BETA_RANGE[0]), BETA_RANGE[1]))


def branches(omega: float, height_pos_deg: float, height_neg_deg: float, d_pos: float,
             d_neg: float, beta_pos: float, beta_neg: float, x0_pos: float, x0_neg: float
             ) -> Branches:
    """The two branches from the loaded lines, plateaus and release lines.

    rising  = H_pos + omega max(x - D_pos, 0) + min(R_neg(x) - H_pos, 0)
    falling = H_neg + omega min(x - D_neg, 0) + max(R_pos(x) - H_neg, 0)
    then lower/upper envelope of the two (continuous and invertible for any parameters).
    """
    w, h_pos, h_neg = omega, height_pos_deg, height_neg_deg
    s_pos, c_pos = release_line(w, h_pos, d_pos, beta_pos, x0_pos)
    s_neg, c_neg = release_line(w, h_neg, d_neg, beta_neg, x0_neg)

    def rising(x: float) -> float:
        return h_pos + w * max(x - d_pos, 0.0) + min(s_neg * x + c_neg - h_pos, 0.0)

    def falling(x: float) -> float:
        return h_neg + w * min(x - d_neg, 0.0) + max(s_pos * x + c_pos - h_neg, 0.0)

    return envelopes({-_FAR_DEG, _FAR_DEG, d_pos, d_neg, (h_pos - c_neg) / s_neg,
                      (h_neg - c_pos) / s_pos}, rising, falling, w)


def envelopes(kinks: set[float], rising: Callable[[float], float],
              falling: Callable[[float], float], omega: float) -> Branches:
    """The lower and upper envelopes of two piecewise-linear branches, exact at their
    ``kinks`` and where the branches cross (the envelopes have a kink there too)."""
    knots = sorted(k for k in kinks if -_FAR_DEG <= k <= _FAR_DEG)
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
        tilt = _FLAT_SLOPE * omega * x
        lo.append(min(r, f) + tilt)
        hi.append(max(r, f) + tilt)
    return Branches(tuple(xs), tuple(lo), tuple(hi), widest_flat(xs, lo, omega),
                    widest_flat(xs, hi, omega))


class PlayState(NamedTuple):
    """Command x, model output y, direction of motion, output held since the last reversal,
    the rounded release's half-width since then (0: a sharp corner), the release line drawn at
    that reversal (:mod:`tsmd.compensation.reversal_release`: its end on the plateau and slope;
    slope 0: the static branches)."""

    x_deg: float
    y_deg: float
    direction: int
    held_deg: float
    round_deg: float = 0.0
    line_x_deg: float = 0.0
    line_y_deg: float = 0.0
    line_slope: float = 0.0


def reversal_release_line(b: Branches, x_deg: float, held_deg: float, direction: int
                          ) -> tuple[float, float, float]:
    """The release line after a reversal at ``x_deg`` holding ``held_deg`` (end knob deg, end
    output deg, slope; slope 0: none): from the static branch's backlash end to the product's
    end on the far plateau, where it meets the branch it hands over to."""
    if b.release_end is None:
        return 0.0, 0.0, 0.0
    if direction < 0:
        flat = b.falling_flat
        if flat is None:
            return 0.0, 0.0, 0.0
        xf = flat.hi_deg
        return reversal_line(b.release_end, x_deg, held_deg, b.falling_inverse(held_deg), xf,
                             lambda x: b.falling(x if x < xf else xf), -1)
    flat = b.rising_flat
    if flat is None:
        return 0.0, 0.0, 0.0
    xl = flat.lo_deg
    return reversal_line(b.release_end, x_deg, held_deg, b.rising_inverse(held_deg), xl,
                         lambda x: b.rising(x if x > xl else xl), 1)


def line_output(b: Branches, x_deg: float, s: PlayState) -> float:
    """The output on a reversal's release line ``L`` (up to its end): moving down
    ``min(held, max(L, F(min(x, x_flat)), R))`` (the falling branch beyond its flat's end held
    at the flat), mirrored moving up."""
    if s.direction < 0:
        flat = b.falling_flat
        f = b.falling(x_deg if flat is None or x_deg < flat.hi_deg else flat.hi_deg)
        if x_deg > s.line_x_deg:
            f = max(f, s.line_y_deg + s.line_slope * (x_deg - s.line_x_deg))
        f = max(f, b.rising(x_deg))
        return s.held_deg if f > s.held_deg else f
    flat = b.rising_flat
    f = b.rising(x_deg if flat is None or x_deg > flat.lo_deg else flat.lo_deg)
    if x_deg < s.line_x_deg:
        f = min(f, s.line_y_deg + s.line_slope * (x_deg - s.line_x_deg))
    f = min(f, b.falling(x_deg))
    return s.held_deg if f < s.held_deg else f


def line_input(b: Branches, y_deg: float, s: PlayState) -> float:
    """The input :func:`line_output` turns into ``y_deg`` (exact: every piece is increasing,
    so the first piece to reach ``y_deg`` sets it)."""
    if s.direction < 0:
        x = b.rising_inverse(y_deg)
        if y_deg > s.line_y_deg:
            x = min(x, s.line_x_deg + (y_deg - s.line_y_deg) / s.line_slope)
        flat = b.falling_flat
        if flat is None or y_deg <= b.falling(flat.hi_deg):
            x = min(x, b.falling_inverse(y_deg))
        return x
    x = b.falling_inverse(y_deg)
    if y_deg < s.line_y_deg:
        x = max(x, s.line_x_deg + (y_deg - s.line_y_deg) / s.line_slope)
    flat = b.rising_flat
    if flat is None or y_deg >= b.rising(flat.lo_deg):
        x = max(x, b.rising_inverse(y_deg))
    return x


def reversal_round(b: Branches, x_deg: float, held_deg: float, direction: int) -> float:
    """The rounded release's half-width after a reversal at ``x_deg`` holding ``held_deg``."""
    if direction < 0:
        k = b.round_pos_deg
        return 0.0 if k == 0.0 else reversal_round_deg(k, b.falling(x_deg) - held_deg)
    k = b.round_neg_deg
    return 0.0 if k == 0.0 else reversal_round_deg(k, held_deg - b.rising(x_deg))


def model_step(state: PlayState, x_deg: float, b: Branches) -> PlayState:
    """Forward model: the output for input ``x_deg`` (the play between the two branches)."""
    dx = x_deg - state.x_deg
    direction = state.direction if dx == 0.0 else (1 if dx > 0.0 else -1)
    if direction == state.direction:
        held, k = state.held_deg, state.round_deg
        lx, ly, slope = state.line_x_deg, state.line_y_deg, state.line_slope
    else:
        held = state.y_deg
        lx, ly, slope = reversal_release_line(b, state.x_deg, held, direction)
        k = 0.0 if slope > 0.0 else reversal_round(b, state.x_deg, held, direction)
    if slope > 0.0:
        nxt = PlayState(x_deg, held, direction, held, 0.0, lx, ly, slope)
        return nxt._replace(y_deg=line_output(b, x_deg, nxt))
    if k > 0.0:  # rounded, and never beyond the other branch (a hold on its flat part)
        if direction > 0:
            y = min(held + rounded_drop_deg(b.rising(x_deg) - held, k), b.falling(x_deg))
        else:
            y = max(held - rounded_drop_deg(held - b.falling(x_deg), k), b.rising(x_deg))
    else:
        y = max(held, b.rising(x_deg)) if direction > 0 else min(held, b.falling(x_deg))
    return PlayState(x_deg, y, direction, held, k)


def inverse_step(state: PlayState, y_deg: float, b: Branches) -> PlayState:
    """The input that makes the model output ``y_deg`` next (exact on sloped parts).

    An unchanged output keeps a held input; one on a branch follows the branch forward if the
    branches moved (the other knob's angle changed the dead zone).
    """
    if y_deg - y_deg != 0.0:  # not finite
        return state
    x_prev, y_prev, direction, held, k, lx, ly, slope = state
    turned = False
    if y_deg == y_prev:
        if y_prev == held:
            return state
    else:
        turn = 1 if y_deg > y_prev else -1
        if turn != direction:
            direction, held, turned = turn, y_prev, True
            lx, ly, slope = reversal_release_line(b, x_prev, held, direction)
            k = 0.0 if slope > 0.0 else reversal_round(b, x_prev, held, direction)
    if slope > 0.0:
        line = PlayState(x_prev, y_deg, direction, held, 0.0, lx, ly, slope)
        x = line_input(b, y_deg, line)
        if (x - x_prev) * direction < 0.0:
            x = x_prev
        if turned and x == x_prev:
            return state._replace(x_deg=x, y_deg=y_deg)
        return line._replace(x_deg=x)
    if direction > 0:
        if k > 0.0 and held < y_deg < held + k:  # on the rounded corner, or the other branch
            x = max(interp_linear(held + rounded_gap_deg(y_deg - held, k), b.rising_deg,
                                  b.knots), interp_linear(y_deg, b.falling_deg, b.knots))
        else:
            x = interp_linear(y_deg, b.rising_deg, b.knots)
        if x < x_prev:
            x = x_prev
    else:
        if k > 0.0 and held - k < y_deg < held:
            x = min(interp_linear(held - rounded_gap_deg(held - y_deg, k), b.falling_deg,
                                  b.knots), interp_linear(y_deg, b.rising_deg, b.knots))
        else:
            x = interp_linear(y_deg, b.falling_deg, b.knots)
        if x > x_prev:
            x = x_prev
    if turned and x == x_prev:
        # the knob does not move, so the catheter sees no reversal: a rounded release goes on,
        # and none starts later from a turn the model never made
        return state._replace(x_deg=x, y_deg=y_deg)
    return PlayState(x, y_deg, direction, held, k)


def rest_state(y_deg: float, b: Branches, home_deg: float = 0.0) -> PlayState:
    """A knob brought to output ``y`` from ``home_deg`` and stopped (at start-up)."""
    lo, hi = b.falling_inverse(y_deg), b.rising_inverse(y_deg)
    if lo <= home_deg <= hi:
        return PlayState(home_deg, y_deg, 1, y_deg)
    if hi < home_deg:  # arrived moving down along the falling branch
        return PlayState(lo, y_deg, -1, max(y_deg, b.falling(home_deg)))
    return PlayState(hi, y_deg, 1, min(y_deg, b.rising(home_deg)))
