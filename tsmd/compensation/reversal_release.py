"""A release per reversal: the tip's release ends where the load at the reversal says
(session 23).

The tension play's release is one line per side, through the ends of all backlashes (its slope
``omega / (1 - beta)`` from the unit's current); it meets the far plateau at one knob angle
whatever the reversal. A tip whose release ends further out after larger reversals (cyclopebax:
about 23 deg after +-45, 30-33 after +-90; docs/model.md "Session 22") cannot follow one line.
Here each reversal draws its own release: from the unit's own backlash end (the current's beta
and x0, unmoved) to an end point on the far plateau at ``ratio(|x_r| / 90) * x_end``, where
``x_end`` is where the unit's release line meets the plateau (the locus its current gives at
the calibration's +-90 deg) and ``ratio`` the product's shape (:class:`ReleaseEndShape`, the
data sheet's ``release_end_shape``, read from unit 0's tip by ``tsmd datasheet``).

The line is state set at the reversal (:class:`tsmd.compensation.tension_play.PlayState`), not a
static branch: moving down, ``y = min(held, max(L(x), F(min(x, x_end)), R(x)))`` with ``L`` the
reversal's line, ``F`` the falling branch (its flat and far loaded part) and ``R`` the rising
branch; every piece is increasing, so the inverse (the smallest of the pieces' inverses) is exact.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

REFERENCE_REVERSAL_DEG = 90.0
"""The reversal whose release end the unit's current gives (the calibration's amplitude)."""
FRACTION_RANGE: tuple[float, float] = (0.05, 2.0)
"""Reversal angles (over :data:`REFERENCE_REVERSAL_DEG`) a shape may be given at."""
END_RATIO_RANGE: tuple[float, float] = (0.2, 2.0)
"""Plausible release ends over the static line's."""
SLOPE_RATIO_RANGE: tuple[float, float] = (0.3, 2.0)
"""Plausible release slopes over the static line's."""
MIN_RUN_DEG = 0.5
"""The shortest release (knob deg from backlash end to end point): a reversal whose end would
lie at or past its backlash end (barely out of the dead zone) releases this steeply."""


@dataclass(frozen=True)
class ReleaseEndShape:
    """The product's release after a reversal at ``fraction`` x 90 deg (mirrored to the
    positive side), against the unit's static release line: where it ends on the plateau
    (``end_ratio`` x the static line's end) and how steep it is (``slope_ratio`` x the static
    line's slope); linear between the knots, held beyond them."""

    reversal_fraction: tuple[float, ...]
    end_ratio: tuple[float, ...]
    slope_ratio: tuple[float, ...]

    def __post_init__(self) -> None:
        xs = self.reversal_fraction
        if len(xs) < 1 or len(xs) != len(self.end_ratio) or len(xs) != len(self.slope_ratio):
            raise ValueError("reversal_fraction, end_ratio and slope_ratio need the same number "
                             "(>= 1) of values")
        if any(b <= a for a, b in itertools.pairwise(xs)):
            raise ValueError("reversal_fraction must be strictly increasing")
        for name, values, (lo, hi) in (("reversal_fraction", xs, FRACTION_RANGE),
                                       ("end_ratio", self.end_ratio, END_RATIO_RANGE),
                                       ("slope_ratio", self.slope_ratio, SLOPE_RATIO_RANGE)):
            for v in values:
                if not (math.isfinite(v) and lo <= v <= hi):
                    raise ValueError(f"{name}: {v} is outside [{lo}, {hi}]")

    def at(self, fraction: float) -> tuple[float, float]:
        """(end ratio, slope ratio) after a reversal at ``fraction`` of the reference one."""
        return _interp(fraction, self.reversal_fraction, self.end_ratio), _interp(
            fraction, self.reversal_fraction, self.slope_ratio)


def _interp(x: float, xs: tuple[float, ...], ys: tuple[float, ...]) -> float:
    if not x > xs[0]:  # also NaN
        return ys[0]
    for i in range(1, len(xs)):
        if x <= xs[i]:
            return ys[i - 1] + (x - xs[i - 1]) / (xs[i] - xs[i - 1]) * (ys[i] - ys[i - 1])
    return ys[-1]


_KEYS = ("reversal_fraction", "end_ratio", "slope_ratio")


def release_end_shape_from_mapping(m: Any, where: str) -> ReleaseEndShape:
    """Validate a ``release_end_shape`` block (ValueError naming ``where``)."""
    if not isinstance(m, Mapping) or set(m) != set(_KEYS):
        raise ValueError(f"{where}: needs exactly {', '.join(_KEYS)}")
    values = []
    for key in _KEYS:
        v = m[key]
        if isinstance(v, str) or not isinstance(v, list | tuple) or any(
                isinstance(x, bool) or not isinstance(x, int | float) for x in v):
            raise ValueError(f"{where}.{key}: must be a list of numbers")
        values.append(tuple(float(x) for x in v))
    try:
        return ReleaseEndShape(values[0], values[1], values[2])
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None


def release_end_shape_to_mapping(s: ReleaseEndShape) -> dict[str, list[float]]:
    return {"reversal_fraction": list(s.reversal_fraction), "end_ratio": list(s.end_ratio),
            "slope_ratio": list(s.slope_ratio)}


def reversal_line(shape: ReleaseEndShape | None, x_rev_deg: float, held_deg: float,
                  backlash_end_deg: float, flat_end_deg: float,
                  level_deg: Callable[[float], float], direction: int
                  ) -> tuple[float, float, float]:
    """The release line after a reversal at ``x_rev_deg`` holding ``held_deg``, moving in
    ``direction``: (end knob deg, end output deg, slope), slope 0 where none is drawn (no shape,
    the hold not beyond the far plateau). The static line runs from the unit's backlash end
    (``backlash_end_deg``) to ``flat_end_deg`` on the plateau (``level_deg``: the output of the
    branch it hands over to); this one ends at ``end_ratio x flat_end_deg`` with ``slope_ratio``
    times its slope, and meets the hold where that puts it, never after the reversal itself
    (then it starts there) and never less than :data:`MIN_RUN_DEG` of knob travel long."""
    if shape is None:
        return 0.0, 0.0, 0.0
    side = -direction  # a reversal moving down came from the positive side
    xf, xb, xr = flat_end_deg * side, backlash_end_deg * side, x_rev_deg * side
    static_drop = (held_deg - level_deg(flat_end_deg)) * side
    if not xf > 0.0 or not static_drop > 0.0 or not xb > xf:
        return 0.0, 0.0, 0.0  # no plateau on the far side, or the hold not beyond it
    end_ratio, slope_ratio = shape.at(xr / REFERENCE_REVERSAL_DEG)
    end = end_ratio * xf
    end_y = level_deg(end * side)
    drop = (held_deg - end_y) * side
    start = min(end + drop / (slope_ratio * static_drop / (xb - xf)) if drop > 0.0 else xr, xr)
    if start - end < MIN_RUN_DEG:
        end = start - MIN_RUN_DEG
        end_y = level_deg(end * side)
        drop = (held_deg - end_y) * side
    if not drop > 0.0:
        return 0.0, 0.0, 0.0
    return end * side, end_y, drop / (start - end)
