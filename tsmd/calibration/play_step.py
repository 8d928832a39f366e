"""Where a handle's play closes after a reversal: a lone step in the flat current (session 24).

On a geared handle whose drum a bearing holds (planetwist's planetary stage), a reversal first
lets the loaded rope go (the current swings to its release level), then the stage's play opens
while the drum stands: the knob turns against its own friction only and the current is flat.
Where the far flanks meet, the drum turns again, the tip moves back, and the motor's torque
steps by the drum bearing's friction through the stage (7-13 mA, planetwist development units
1-4). The release rules read the first part only; the play's length scatters from unit to unit
(+-30 %), so a reading offset measured on the data sheet's unit carries that unit's play to
every other. Where the product's sheet says the step marks its tip's release
(``DeviceKnob.backlash_play_step``, chosen by :mod:`tsmd.datasheet_play_step`), each
half-cycle's backlash ends at its own step; a half-cycle whose current shows no clear step
gives no backlash (its rule's end would need the offset the step reading does not carry).

The step is the largest difference between the current's means over ``PLAY_STEP_WINDOW_DEG``
after and before a point, searched from where the swing after the reversal has ended (the
difference first changes sign) to the release branch's end; it counts when it stands
``PLAY_STEP_CLEAR`` robust standard deviations (1.4826 x MAD) of the differences elsewhere on
that stretch away from zero.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from tsmd.calibration.signal import FloatArray

PLAY_STEP_WINDOW_DEG = 2.0
"""Knob travel each side of a candidate over which the current is averaged: wider than the
step's own rise (0.5 deg at the motor's speed) and the filter's ringing, short against the
flat stretch (the play is 7-15 knob deg)."""
PLAY_STEP_CLEAR = 4.5
"""A step counts where it stands this many robust standard deviations of the mean differences
elsewhere on the stretch away from zero: one event, not the noise's largest swing (planetwist
development units 1-4: steps 5.5-10, median 9.1; the largest swing of the 100 deg after each
step, noise and the release branch's slope, 2.9 median, 5.0 at most over 96 half-cycles)."""


@dataclasses.dataclass(frozen=True)
class PlayStep:
    """A step found in one half-cycle's current (indices into its angle grid)."""

    index: int
    size_A: float
    """Signed (direction-signed current after minus before)."""
    clearness: float
    """|size| over the robust standard deviation of the mean differences elsewhere."""


def mean_differences(yg: FloatArray, half: int) -> FloatArray:
    """Per grid point k (``half`` <= k < size - ``half``): mean of the next ``half`` points
    minus mean of the previous ``half``; NaN at the ends."""
    out = np.full(yg.size, math.nan)
    if yg.size < 2 * half + 1:
        return out
    cs = np.concatenate([[0.0], np.cumsum(yg)])
    k = np.arange(half, yg.size - half)
    out[k] = ((cs[k + half] - cs[k]) - (cs[k] - cs[k - half])) / half
    return out


def find_play_step(yg: FloatArray, step_deg: float, stop: int | None = None) -> PlayStep | None:
    """The lone step in the direction-signed current ``yg`` (on a grid of ``step_deg`` from the
    reversal) before ``stop``, or None where none stands out (:data:`PLAY_STEP_CLEAR`)."""
    half = max(2, round(PLAY_STEP_WINDOW_DEG / step_deg))
    last = yg.size if stop is None else min(stop, yg.size)
    diff = mean_differences(yg[:last], half)
    finite = np.flatnonzero(np.isfinite(diff))
    if finite.size == 0:
        return None
    # The swing after the reversal ends where the difference first turns its sign.
    first = diff[finite[0]]
    turned = finite[np.sign(diff[finite]) != np.sign(first)]
    if turned.size == 0:
        return None
    a = int(turned[0]) + half
    if last - half - a < 4 * half:
        return None
    seg = diff[a:last - half]
    k = int(np.argmax(np.abs(seg)))
    rest = np.concatenate([seg[:max(0, k - 2 * half)], seg[k + 2 * half:]])
    if rest.size < 4 * half:
        return None
    sigma = 1.4826 * float(np.median(np.abs(rest - np.median(rest))))
    clearness = float(abs(seg[k]) / max(sigma, 1e-12))
    if clearness < PLAY_STEP_CLEAR:
        return None
    return PlayStep(a + k, float(seg[k]), clearness)
