"""Feed-forward dead-zone + backlash compensation: desired knob angles -> motor commands.

``build_compensator(profile, method, period_s, limits)`` gives a :class:`Compensator`:
``"none"`` passes the desired angles through, ``"paper"`` is the published piecewise-linear
inverse (:mod:`tsmd.compensation.paper`), ``"ours"`` the inverse of the tension play
(:mod:`tsmd.compensation.tension_play`, run by :mod:`tsmd.compensation.ours`), every parameter
identified per catheter from its calibration current. With ``limits`` the output goes through
the rate and position limiter of :mod:`tsmd.compensation.safety` last, so it never leaves the
knobs' range.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from tsmd.compensation.grid import ParameterField
from tsmd.compensation.ours import OursCompensator
from tsmd.compensation.ours_table import ours_knobs
from tsmd.compensation.paper import PaperCompensator, PaperKnob
from tsmd.compensation.safety import KnobLimiter, KnobLimits
from tsmd.errors import TsmdError

if TYPE_CHECKING:
    from tsmd.profile import CatheterProfile

METHODS: tuple[str, ...] = ("none", "paper", "ours")
"""Also the config's ``CompensationMethod`` (a test keeps the two equal)."""
RENAMED_METHODS: dict[str, str] = {"tension": "ours"}
"""Former method names, refused with the name to use (one line)."""

__all__ = [
    "METHODS",
    "CompensationError",
    "Compensator",
    "FollowsMotor",
    "KnobLimiter",
    "KnobLimits",
    "LimitedCompensator",
    "NoCompensation",
    "Previewing",
    "build_compensator",
]


class CompensationError(TsmdError, ValueError):
    """The compensator cannot be built as asked (unknown method, no profile, missing params)."""


@runtime_checkable
class Compensator(Protocol):
    """Stateful map from desired knob angles to motor commands, called once per tick with the
    time since the last tick (a late tick on a loaded machine covers several periods: what
    counts time, velocity estimates, limits, smoothing, counts it in seconds, not ticks)."""

    def reset(self, q_deg: NDArray[np.float64]) -> None:
        """Start from rest at desired angles ``q_deg`` (shape (2,))."""

    def command(self, q_deg: NDArray[np.float64], dt_s: float) -> NDArray[np.float64]:
        """The motor command (shape (2,), degrees) for this tick's desired angles, ``dt_s``
        seconds after the last tick (the period when ticks are on time)."""


@runtime_checkable
class FollowsMotor(Protocol):
    """A compensator that can stand by: it keeps its model on the branch the catheter is on
    while something else commands the motor, so switching it on mid-motion needs no reset."""

    def follow(self, q_deg: NDArray[np.float64], motor_deg: NDArray[np.float64],
               dt_s: float) -> None:
        """This tick (``dt_s`` after the last) the desired angles were ``q_deg`` and the motor
        was sent ``motor_deg``."""

    def continue_from(self, other: Any) -> None:
        """Take the state of ``other``, a compensator of the same kind for the same catheter."""


class Previewing(Protocol):
    """A compensator that can use the desired angles still to come. The loop playing a
    trajectory calls ``preview`` every tick before ``command``, with the whole table (rows of
    two angles) and this tick's row; a compensator uses the plan only in the tick it was
    given (a setpoint from a client has none)."""

    def preview(self, plan_deg: Sequence[Sequence[float]], index: int) -> None:
        """This tick's desired angles are ``plan_deg[index]``; the rows after it follow."""


class NoCompensation:
    """Sends the desired angles as they are (non-finite values hold the last command)."""

    def __init__(self) -> None:
        self._last = np.zeros(2)

    def reset(self, q_deg: NDArray[np.float64]) -> None:
        q = np.asarray(q_deg, dtype=float)
        self._last = np.where(np.isfinite(q), q, 0.0)

    def command(self, q_deg: NDArray[np.float64], dt_s: float) -> NDArray[np.float64]:
        q = np.asarray(q_deg, dtype=float)
        self._last = np.where(np.isfinite(q), q, self._last)
        return self._last.copy()

    def follow(self, q_deg: NDArray[np.float64], motor_deg: NDArray[np.float64],
               dt_s: float) -> None:
        motor = np.asarray(motor_deg, dtype=float)
        self._last = np.where(np.isfinite(motor), motor, self._last)

    def continue_from(self, other: NoCompensation) -> None:
        self._last = other._last.copy()


class LimitedCompensator:
    """Any compensator followed by the knob limiter (offline use: the loop limits by itself)."""

    def __init__(self, inner: Compensator, limits: Sequence[KnobLimits], period_s: float) -> None:
        if len(limits) != 2:
            raise CompensationError(f"need limits for 2 knobs, got {len(limits)}")
        self.inner = inner
        self.limiter = KnobLimiter(limits, period_s)
        self.last_unlimited = np.zeros(2)

    @property
    def limits(self) -> tuple[KnobLimits, ...]:
        return self.limiter.limits

    def reset(self, q_deg: NDArray[np.float64]) -> None:
        self.inner.reset(q_deg)
        q = np.asarray(q_deg, dtype=float)
        start = self.inner.command(q, self.limiter.dt_s)
        self.inner.reset(q_deg)
        first = [lim.clip(float(x)) if np.isfinite(x) else 0.0
                 for x, lim in zip(start, self.limits, strict=True)]
        self.limiter.reset(np.array(first), hold=True)

    def command(self, q_deg: NDArray[np.float64], dt_s: float) -> NDArray[np.float64]:
        raw = self.inner.command(q_deg, dt_s)
        self.last_unlimited = np.asarray(raw, dtype=float).copy()
        return self.limiter.limit(raw, dt_s)

    def follow(self, q_deg: NDArray[np.float64], motor_deg: NDArray[np.float64],
               dt_s: float) -> None:
        if isinstance(self.inner, FollowsMotor):
            self.inner.follow(q_deg, motor_deg, dt_s)
        self.limiter.limit(np.asarray(motor_deg, dtype=float))  # the limiter where the motor is

    def continue_from(self, other: LimitedCompensator) -> None:
        if isinstance(self.inner, FollowsMotor):
            self.inner.continue_from(other.inner)
        self.limiter = copy.deepcopy(other.limiter)


def paper_compensator(profile: CatheterProfile) -> PaperCompensator:
    """The paper's model per knob, fed the knob's paper frame (:meth:`KnobProfile.for_paper`)."""
    knobs = tuple(PaperKnob(ParameterField.from_columns(k.other_knob_deg, {
                      "dead_zone_pos_deg": k.dead_zone_pos_deg,
                      "dead_zone_neg_deg": k.dead_zone_neg_deg,
                      "backlash_pos_deg": k.backlash_pos_deg,
                      "backlash_neg_deg": k.backlash_neg_deg}, profile.interpolation),
                            k.height_pos_deg, k.height_neg_deg, k.omega)
                  for k in (knob.for_paper() for knob in profile.knobs))
    return PaperCompensator((knobs[0], knobs[1]))


def ours_compensator(profile: CatheterProfile, period_s: float,
                     limits: Sequence[KnobLimits] | None = None,
                     fresh_catheter: bool = False) -> OursCompensator:
    """The tension play's inverse from the profile's per-knob ``tension_play`` parameters."""
    params = [k.tension_play for k in profile.knobs]
    if params[0] is None or params[1] is None:
        raise CompensationError(
            f"profile {profile.catheter_id!r} has no parameters for method 'ours' (it was "
            "calibrated by an older tsmd): recalibrate it, or use method 'paper'")
    return OursCompensator(ours_knobs((params[0], params[1]), profile.interpolation),
                           period_s, limits, fresh_catheter=fresh_catheter)


def build_compensator(profile: CatheterProfile | None, method: str, period_s: float,
                      limits: Sequence[KnobLimits] | None = None, *,
                      apply_limits: bool = True, fresh_catheter: bool = False) -> Compensator:
    """The compensator for ``method`` ("none" | "paper" | "ours"), limited when ``limits``.

    ``apply_limits=False`` only informs the compensator of the motor's limits (ours plans its
    jumps and limits its own command with them): for a caller such as the control loop that
    applies the limiter itself, last. ``fresh_catheter``: ours starts on a never-loaded
    catheter's branches (:class:`OursCompensator`).
    """
    if method in RENAMED_METHODS:
        raise CompensationError(f"compensation method {method!r} is now called "
                                f"{RENAMED_METHODS[method]!r}")
    if method not in METHODS:
        raise CompensationError(f"compensation method {method!r} is not one of {list(METHODS)}")
    if not period_s > 0:
        raise CompensationError(f"period_s must be positive, got {period_s}")
    inner: Compensator
    if method == "none":
        inner = NoCompensation()
    elif profile is None:
        raise CompensationError(f"compensation method {method!r} needs a catheter profile")
    elif method == "paper":
        inner = paper_compensator(profile)
    else:
        inner = ours_compensator(profile, period_s, limits, fresh_catheter)
    if limits is None or not apply_limits:
        return inner
    return LimitedCompensator(inner, limits, period_s)
