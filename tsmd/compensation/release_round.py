"""A rounded release: the tip leaves its hold gradually after a reversal (session 20).

The tension play holds the output for the backlash the current reads, then drops on the release
line: a sharp corner. The tip starts back gradually (nitinol: it leaves the hold where the
current says, but the straight part of its release lies 30-40 % of a backlash later). Here the
corner where the hold meets a branch is a parabola of half-width ``k`` (output degrees) tangent
to both, and the release line may lie ``shift`` later along the knob axis. Both are product
fractions (data sheet, measured on its unit) of each unit's own backlash at a
:data:`REFERENCE_REVERSAL_DEG` reversal as its current reads it, so they scale with the unit.

Moving down after a reversal, with ``u = held - branch(x)`` (negative while held):
``y = held - drop(u)``, ``drop = 0`` for ``u <= -k``, ``(u + k)^2 / 4k`` inside, ``u`` beyond
``k``: continuous with a continuous slope, monotone in ``u``, exactly invertible
(:func:`rounded_gap_deg`). At a reversal ``k`` is limited to the gap between the hold and the
branch there, so the output never jumps (a reversal inside the dead zone keeps a sharp corner).
"""

from __future__ import annotations

import math

REFERENCE_REVERSAL_DEG = 90.0
"""The reversal whose backlash scales a unit's rounding and shift (the calibration's amplitude)."""
RELEASE_ROUND_RANGE: tuple[float, float] = (0.0, 1.0)
"""Half-width of the rounding, in backlashes at the reference reversal."""
RELEASE_SHIFT_RANGE: tuple[float, float] = (-0.5, 1.0)
"""How much later the release line lies, in backlashes at the reference reversal."""


def rounded_drop_deg(gap_deg: float, k_deg: float) -> float:
    """How far the output has left the hold, the branch ``gap_deg`` past the hold."""
    if gap_deg >= k_deg:
        return gap_deg
    if gap_deg <= -k_deg:
        return 0.0
    s = gap_deg + k_deg
    return s * s / (4.0 * k_deg)


def rounded_gap_deg(drop_deg: float, k_deg: float) -> float:
    """The inverse of :func:`rounded_drop_deg` for ``drop_deg > 0``."""
    if drop_deg >= k_deg:
        return drop_deg
    return 2.0 * math.sqrt(k_deg * drop_deg) - k_deg


def reversal_round_deg(k_deg: float, gap_deg: float) -> float:
    """The half-width used after a reversal where the branch lies ``gap_deg`` beyond the hold:
    never more than that gap (the output starts on the hold)."""
    if gap_deg <= 0.0:
        return 0.0
    return k_deg if k_deg < gap_deg else gap_deg


def reference_backlash_deg(beta: float, zero_load_deg: float, side: int) -> float:
    """The unit's backlash (knob deg) after a reversal at +-:data:`REFERENCE_REVERSAL_DEG`."""
    return max(beta * (REFERENCE_REVERSAL_DEG - side * zero_load_deg), 0.0)


def shifted_zero_load_deg(beta: float, zero_load_deg: float, shift: float, side: int) -> float:
    """The zero-load point that puts every backlash end of a side ``shift`` reference backlashes
    later (a parallel release line: ``beta (x_r - x0')`` = ``beta (x_r - x0) + shift B_ref``)."""
    return zero_load_deg - side * shift * (REFERENCE_REVERSAL_DEG - side * zero_load_deg)
