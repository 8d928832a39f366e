"""The paper's piecewise-linear dead-zone + backlash model L and its inverse F.

Notation follows the paper (section "Modeling non-linear hysteresis using piecewise linear
approximation"): for one knob, the input x is the knob angle and the output y the tip angle.
Moving up (positive velocity) the output follows L2 -> L3 -> L4, moving down L6 -> L7 -> L8;
after a reversal it holds on the backlash line L1 (now moving up) or L5 (now moving down) at the
output it had at the reversal, until it meets the branch of the new direction.

The rising branch ``L2/L3/L4`` and the falling branch ``L6/L7/L8`` are the two envelopes of a
play operator; holding the output between them on the backlash lines is exactly the paper's
reference-point update (the reference point is wherever the output was when the velocity changed
sign). docs/model.md explains the decisions taken where the paper's figures are missing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tsmd.compensation.grid import ParameterField


class Line(IntEnum):
    """The eight lines of Eq. (model_eqs)."""

    L1 = 1  # backlash after a reversal to positive velocity (held output)
    L2 = 2  # rising, below the dead zone: omega*(x - D_hat_pos) + H_pos
    L3 = 3  # rising, dead zone: H_pos
    L4 = 4  # rising, above the dead zone: omega*(x - D_pos) + H_pos
    L5 = 5  # backlash after a reversal to negative velocity (held output)
    L6 = 6  # falling, above the dead zone: omega*(x - D_hat_neg) + H_neg
    L7 = 7  # falling, dead zone: H_neg
    L8 = 8  # falling, below the dead zone: omega*(x - D_neg) + H_neg


_FLAT = (Line.L3, Line.L7)


@dataclass(frozen=True)
class PaperParams:
    """One knob's parameters at one angle of the other knob (all angles signed, degrees).

    ``dead_zone_neg_deg`` (D_neg) is normally negative, ``dead_zone_pos_deg`` (D_pos) positive.
    ``height_*_deg`` (H) are tip angles; ``omega`` is tip degrees per knob degree.
    """

    dead_zone_pos_deg: float
    dead_zone_neg_deg: float
    backlash_pos_deg: float
    backlash_neg_deg: float
    height_pos_deg: float
    height_neg_deg: float
    omega: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.omega) and self.omega > 0):
            raise ValueError(f"omega must be a positive finite slope, got {self.omega}")

    @property
    def d_hat_pos_deg(self) -> float:
        """Eq. (D_hats): where the rising branch enters the dead zone."""
        return ((self.height_pos_deg - self.height_neg_deg) / self.omega
                + self.dead_zone_neg_deg + self.backlash_neg_deg)

    @property
    def d_hat_neg_deg(self) -> float:
        """Eq. (D_hats): where the falling branch enters the dead zone."""
        return ((self.height_neg_deg - self.height_pos_deg) / self.omega
                + self.dead_zone_pos_deg - self.backlash_pos_deg)

    # The dead-zone interval of each branch. If the identified numbers make it negative (D_hat past
    # D), the flat part collapses to a point at its midpoint so both branches stay monotone.
    def rising_flat(self) -> tuple[float, float]:
        """[start, end] of L3 on the input axis."""
        return _ordered(self.d_hat_pos_deg, self.dead_zone_pos_deg)

    def falling_flat(self) -> tuple[float, float]:
        """[start, end] of L7 on the input axis."""
        return _ordered(self.dead_zone_neg_deg, self.d_hat_neg_deg)


def _ordered(lo: float, hi: float) -> tuple[float, float]:
    if lo <= hi:
        return lo, hi
    mid = 0.5 * (lo + hi)
    return mid, mid


def height_from_reference(reference_knob_deg: float, reference_tip_deg: float,
                          dead_zone_deg: float, omega: float) -> float:
    """H from design assumptions 1-3: the line of slope omega through the reference point
    (X_ref, Y_ref) measured with the other knob at 0 deg, evaluated at the dead-zone end D."""
    return reference_tip_deg - omega * (reference_knob_deg - dead_zone_deg)


class ReferenceConstants(Protocol):
    """What H needs from a data sheet's knob (``tsmd.profile.DeviceKnob`` and ``KnobProfile``)."""

    @property
    def omega(self) -> float: ...
    @property
    def reference_pos(self) -> ReferenceLike: ...
    @property
    def reference_neg(self) -> ReferenceLike: ...


class ReferenceLike(Protocol):
    @property
    def knob_deg(self) -> float: ...
    @property
    def tip_deg(self) -> float: ...


def plateau_heights(constants: ReferenceConstants, dead_zone_pos_at_zero_deg: float,
                    dead_zone_neg_at_zero_deg: float) -> tuple[float, float]:
    """(H_pos, H_neg): :func:`height_from_reference` at both reference points, with the edges
    the catheter shows with the other knob at 0 deg (where the reference points were measured).

    The one place H is computed: profiles, compensators and calibration all call this.
    """
    h_pos = height_from_reference(constants.reference_pos.knob_deg,
                                  constants.reference_pos.tip_deg, dead_zone_pos_at_zero_deg,
                                  constants.omega)
    h_neg = height_from_reference(constants.reference_neg.knob_deg,
                                  constants.reference_neg.tip_deg, dead_zone_neg_at_zero_deg,
                                  constants.omega)
    return float(h_pos), float(h_neg)


def at_other_knob_zero(other_knob_deg: ArrayLike, values: ArrayLike) -> float:
    """A grid parameter at the other knob's 0 deg (linear between grid points, exact on one)."""
    return float(np.interp(0.0, np.asarray(other_knob_deg, dtype=float),
                           np.asarray(values, dtype=float)))


def offset_edges(dead_zone_pos_deg: ArrayLike, dead_zone_neg_deg: ArrayLike, offset_deg: float
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The current's dead-zone edges moved outward by ``offset_deg`` (data sheet: how far
    outside the current's edge the tip leaves its plateau). The one place the offset is applied."""
    return (np.asarray(dead_zone_pos_deg, dtype=float) + offset_deg,
            np.asarray(dead_zone_neg_deg, dtype=float) - offset_deg)


def _line_rising(x_deg: float, p: PaperParams) -> tuple[float, Line]:
    lo, hi = p.rising_flat()
    if x_deg > hi:
        return p.omega * (x_deg - hi) + p.height_pos_deg, Line.L4
    if x_deg < lo:
        return p.omega * (x_deg - lo) + p.height_pos_deg, Line.L2
    return p.height_pos_deg, Line.L3


def _line_falling(x_deg: float, p: PaperParams) -> tuple[float, Line]:
    lo, hi = p.falling_flat()
    if x_deg > hi:
        return p.omega * (x_deg - hi) + p.height_neg_deg, Line.L6
    if x_deg < lo:
        return p.omega * (x_deg - lo) + p.height_neg_deg, Line.L8
    return p.height_neg_deg, Line.L7


def _preimage(y_deg: float, flat: tuple[float, float], height: float,
              omega: float) -> tuple[float, float]:
    lo, hi = flat
    if y_deg > height:
        x = hi + (y_deg - height) / omega
        return x, x
    if y_deg < height:
        x = lo + (y_deg - height) / omega
        return x, x
    return lo, hi


# The rising branch is the lower envelope of the lines L2/L3/L4 and L6/L7/L8, the falling branch
# the upper one. Wherever the paper's lines are ordered (H_pos <= H_neg + omega*B, always the
# case for H_pos <= H_neg) this changes nothing; where the reference-point construction gives
# H_pos above H_neg, the lines cross in the dead zone and the model would jump there, and the
# envelopes keep it continuous and invertible (docs/model.md, decision 4).


def rising_branch(x_deg: float, p: PaperParams) -> tuple[float, Line]:
    """The output on L2/L3/L4 at input x and which line it is."""
    up = _line_rising(x_deg, p)
    down = _line_falling(x_deg, p)
    return down if down[0] < up[0] else up


def falling_branch(x_deg: float, p: PaperParams) -> tuple[float, Line]:
    """The output on L6/L7/L8 at input x and which line it is."""
    up = _line_rising(x_deg, p)
    down = _line_falling(x_deg, p)
    return up if up[0] > down[0] else down


def rising_preimage(y_deg: float, p: PaperParams) -> tuple[float, float]:
    """All inputs x whose rising-branch output is y, as an interval [lo, hi]."""
    a = _preimage(y_deg, p.rising_flat(), p.height_pos_deg, p.omega)
    b = _preimage(y_deg, p.falling_flat(), p.height_neg_deg, p.omega)
    return max(a[0], b[0]), max(a[1], b[1])


def falling_preimage(y_deg: float, p: PaperParams) -> tuple[float, float]:
    """All inputs x whose falling-branch output is y, as an interval [lo, hi]."""
    a = _preimage(y_deg, p.rising_flat(), p.height_pos_deg, p.omega)
    b = _preimage(y_deg, p.falling_flat(), p.height_neg_deg, p.omega)
    return min(a[0], b[0]), min(a[1], b[1])


@dataclass(frozen=True)
class ModelState:
    """What the model remembers between ticks.

    ``direction`` is +1 or -1: the sign of the last non-zero velocity (standing still keeps it).
    ``reference_deg`` is (X_ref, Y_ref) of the last reversal: where it happened and the output
    held on the backlash line since.
    """

    x_deg: float
    y_deg: float
    direction: int
    reference_deg: tuple[float, float]


def initial_state(x_deg: float, p: PaperParams, direction: int = 1) -> ModelState:
    """The state after arriving at x moving in ``direction`` (on that direction's branch)."""
    y = rising_branch(x_deg, p)[0] if direction >= 0 else falling_branch(x_deg, p)[0]
    d = 1 if direction >= 0 else -1
    return ModelState(x_deg, y, d, (x_deg, y))


def model_step(state: ModelState, x_deg: float, p: PaperParams) -> tuple[ModelState, Line]:
    """L(x_t, xdot_t, xdot_{t-1}): one tick of the forward model.

    The velocity is the sign of ``x_t - x_{t-1}``; zero velocity keeps the previous direction.
    On a reversal the reference point is set to the current (input, output). Then the output is
    the held backlash value until the branch of the current direction passes it.
    """
    dx = x_deg - state.x_deg
    direction = state.direction if dx == 0 else (1 if dx > 0 else -1)
    reference = state.reference_deg
    if direction != state.direction:
        reference = (state.x_deg, state.y_deg)
    # An output that does not change is reported on the backlash line unless the branch itself
    # is flat there (the dead zone): the sloped lines are reported only when the output moves.
    if direction > 0:
        branch_y, line = rising_branch(x_deg, p)
        if branch_y > state.y_deg or (branch_y == state.y_deg and line in _FLAT):
            y = branch_y
        else:
            y, line = state.y_deg, Line.L1
    else:
        branch_y, line = falling_branch(x_deg, p)
        if branch_y < state.y_deg or (branch_y == state.y_deg and line in _FLAT):
            y = branch_y
        else:
            y, line = state.y_deg, Line.L5
    return ModelState(x_deg, y, direction, reference), line


def inverse_step(state: ModelState, y_desired_deg: float, p: PaperParams) -> ModelState:
    """F = L^-1: the input that makes the model output ``y_desired_deg`` from ``state``.

    Desired output up: the rising branch's preimage; down: the falling branch's; unchanged: stay.
    Where the preimage is an interval (the dead zone) the end nearest the previous input is
    taken, so the command moves as little as possible. Crossing a flat part is a jump: that is
    the paper's compensation of the dead zone and backlash (the rate limiter smooths it).
    """
    y = y_desired_deg
    if y > state.y_deg:
        lo, hi = rising_preimage(y, p)
        direction = 1
    elif y < state.y_deg:
        lo, hi = falling_preimage(y, p)
        direction = -1
    else:
        return state
    x = min(max(state.x_deg, lo), hi)
    reference = state.reference_deg if direction == state.direction else (state.x_deg, state.y_deg)
    return ModelState(x, y, direction, reference)


def hold_band(y_deg: float, p: PaperParams) -> tuple[float, float]:
    """Inputs at which an output y is held between the two branches: [lo, hi].

    """
    return falling_preimage(y_deg, p)[0], rising_preimage(y_deg, p)[1]


def rest_state(y_deg: float, p: PaperParams, home_knob_deg: float = 0.0) -> ModelState:
    """The state of a catheter brought to output y from the home knob angle and stopped.

    If the home angle can hold y it stays there; otherwise the knob sits at the loaded end of the
    band (it arrived moving away from home), which is the state reached in practice at start-up.
    """
    lo, hi = hold_band(y_deg, p)
    if lo <= home_knob_deg <= hi:
        x, direction = home_knob_deg, 1
    elif hi < home_knob_deg:
        x, direction = lo, -1
    else:
        x, direction = hi, 1
    return ModelState(x, y_deg, direction, (x, y_deg))


@dataclass(frozen=True)
class PaperKnob:
    """One knob of the paper's compensator: parameters over the other knob's angle + constants."""

    field: ParameterField  # D_pos, D_neg, B_pos, B_neg over the other knob's angle
    height_pos_deg: float
    height_neg_deg: float
    omega: float

    def params(self, other_deg: float) -> PaperParams:
        d_pos, d_neg, b_pos, b_neg = self.field.at(other_deg)
        return PaperParams(float(d_pos), float(d_neg), max(float(b_pos), 0.0),
                           max(float(b_neg), 0.0), self.height_pos_deg, self.height_neg_deg,
                           self.omega)


class PaperCompensator:
    """F for two knobs: each knob's parameters follow the other knob's desired angle every tick,
    as in the paper (the calibration grid is indexed by the other knob's angle)."""

    def __init__(self, knobs: tuple[PaperKnob, PaperKnob]) -> None:
        self.knobs = knobs
        self._states: list[ModelState] = []
        self.reset(np.zeros(2))

    def reset(self, q_deg: NDArray[np.float64]) -> None:
        q = _finite_or_zero(q_deg)
        self._states = [rest_state(float(q[i]), k.params(float(q[1 - i])))
                        for i, k in enumerate(self.knobs)]

    def command(self, q_deg: NDArray[np.float64], dt_s: float) -> NDArray[np.float64]:
        """The inverse of the model at ``q_deg`` (static: the time ``dt_s`` plays no part)."""
        q = np.asarray(q_deg, dtype=float)
        out = np.empty(2)
        for i, knob in enumerate(self.knobs):
            state = self._states[i]
            if math.isfinite(q[i]) and math.isfinite(q[1 - i]):
                state = inverse_step(state, float(q[i]), knob.params(float(q[1 - i])))
                self._states[i] = state
            out[i] = state.x_deg
        return out

    def follow(self, q_deg: NDArray[np.float64], motor_deg: NDArray[np.float64],
               dt_s: float) -> None:
        """The motor was sent ``motor_deg`` by someone else: the model follows it."""
        for i, knob in enumerate(self.knobs):
            x, other = float(motor_deg[i]), float(q_deg[1 - i])
            if math.isfinite(x) and math.isfinite(other):
                self._states[i] = model_step(self._states[i], x, knob.params(other))[0]

    def continue_from(self, other: PaperCompensator) -> None:
        """Take ``other``'s model state (same catheter), keep these parameters."""
        self._states = list(other._states)

    @property
    def states(self) -> tuple[ModelState, ...]:
        return tuple(self._states)


def _finite_or_zero(q_deg: NDArray[np.float64]) -> NDArray[np.float64]:
    q = np.asarray(q_deg, dtype=float).copy()
    q[~np.isfinite(q)] = 0.0
    return q
