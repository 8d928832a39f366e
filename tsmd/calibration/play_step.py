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
difference first changes sign) to ``PLAY_STEP_MAX_DEG`` after the reversal; it counts when it stands
``PLAY_STEP_CLEAR`` times the largest difference elsewhere on that stretch.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from tsmd.calibration.release import RELEASE_LINE_WINDOW_DEG
from tsmd.calibration.signal import FloatArray

PLAY_STEP_WINDOW_DEG = 2.0
"""Knob travel each side of a candidate over which the current is averaged: wider than the
step's own rise (0.5 deg at the motor's speed) and the filter's ringing, short against the
flat stretch (the play is 7-15 knob deg)."""
PLAY_STEP_MAX_DEG = RELEASE_LINE_WINDOW_DEG[0]
"""The search ends this far after the reversal: past the family's largest backlash (31 deg), where
the release line starts; beyond, the release branch's own end (the rope going slack at the
near dead-zone edge) steps the current too (jawcrimp and warmgear unit 0: 55-59 deg)."""
PLAY_STEP_CLEAR = 2.2
"""A step counts where it is this many times the largest mean difference elsewhere on the
stretch: one event, not the noise's largest swing. Planetwist units 0-4 (120 half-cycles):
2.56 at least, 2.83 at the 5th percentile; a white-noise current (2 mA) without a step, 40
half-cycles: 1.84 at the 95th percentile, 2.55 at most (one passes). Measured against the
robust standard deviation instead, the two overlapped (steps from 4.5, noise up to 6.2). Where
the current has a step this only decides whether a half-cycle gives a backlash at all; where
it has none the data sheet's choice keeps the product on its rule
(:mod:`tsmd.datasheet_play_step`)."""


@dataclasses.dataclass(frozen=True)
class PlayStep:
    """A step found in one half-cycle's current (indices into its angle grid)."""

    index: int
    size_A: float
    """Signed (direction-signed current after minus before)."""
    clearness: float
    """|size| over the largest mean difference elsewhere on the stretch."""


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
    last = min(yg.size if stop is None else stop, yg.size, round(PLAY_STEP_MAX_DEG / step_deg))
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
    if rest.size == 0:
        return None
    clearness = float(abs(seg[k]) / max(float(np.max(np.abs(rest))), 1e-12))
    if clearness < PLAY_STEP_CLEAR:
        return None
    return PlayStep(a + k, float(seg[k]), clearness)
