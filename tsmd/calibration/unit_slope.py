"""The unit's loaded slope ``omega`` from its own current, weighed against the data sheet's.

Knob travel on a loaded branch goes partly into tip motion and partly into tendon stretch, the
stretch being what a reversal gives back as backlash; so ``omega_unit = omega_sheet (1 -
beta_unit) / (1 - beta_sheet)`` (:func:`unit_omega`), with both backlash gains read by one rule.
Two rules give such a reading: the settle rule (the sheet's ``reference_backlash_gain``) and the
product's own rule (``reference_rule_backlash_gain``, the B every profile holds). Neither holds
on every product (session 13): the settle rule's B jumps on one side of some coilpipe
units (104 phi1, 103 phi2: omega 9-18 % too shallow), the product rule's on others (segments).
How far the two sides of one reading disagree says which: each reading is weighted by that
scatter, and the sheet's own omega counts as one more reading of known scatter
(:data:`PRODUCT_SLOPE_SCATTER`), so a unit whose current says little keeps the product's slope.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tsmd.compensation.tension_play_params import OMEGA_RANGE

PRODUCT_SLOPE_SCATTER = 0.10
"""A unit's loaded slope against the data sheet's, relative: about this much (tip chords of the
development units, session 13: capstan, coilpipe, segments, stickslip, twistshaft within +-7 %;
lumped's held-out units 0.81-1.14). The sheet's omega is a reading with this uncertainty."""
MIN_READING_SD = 0.003
"""A reading's scatter is never taken as less than this (sides that agree exactly are luck)."""


@dataclass(frozen=True)
class GainReading:
    """One rule's backlash gains: the data-sheet unit's and this unit's (at the other knob's 0,
    mean of both sides) and the scatter of this unit's values (:func:`gain_scatter`)."""

    sheet_gain: float
    unit_gain: float
    unit_sd: float

    def ratio(self) -> float:
        """This unit's slope over the sheet's that the reading says."""
        return (1.0 - self.unit_gain) / (1.0 - self.sheet_gain)

    def ratio_sd(self) -> float:
        """The ratio's uncertainty (inf: no weight)."""
        return max(self.unit_sd, MIN_READING_SD) / (1.0 - self.sheet_gain)


def unit_omega(sheet_omega: float, sheet_backlash_gain: float | None, unit_backlash_gain: float
               ) -> float:
    """The unit's loaded slope: the product's release slope ``omega_sheet / (1 - beta_sheet)``
    times the unit's ``1 - beta`` (its own stretch share); the sheet's omega without
    ``beta_sheet``."""
    if sheet_backlash_gain is None:
        return float(sheet_omega)
    lo, hi = OMEGA_RANGE
    w = sheet_omega * (1.0 - unit_backlash_gain) / (1.0 - sheet_backlash_gain)
    return min(max(float(w), lo), hi)


def gain_scatter(pos_gains: Sequence[float], neg_gains: Sequence[float]) -> float:
    """A reading's scatter: the two sides' gains at each grid point, which one rule should read
    alike, differ by this much (rms of the differences over sqrt 2; inf without a finite pair).
    Across the grid the gains may move with the coupling, a trend and not scatter; a rule that
    misreads B misreads one side and not the other (coilpipe 104 phi1, settle rule: 0.25-0.32
    against 0.40-0.54; product rule 0.21-0.23 on both)."""
    d = np.asarray(pos_gains, float) - np.asarray(neg_gains, float)
    d = d[np.isfinite(d)]
    return float(np.sqrt(np.mean(d**2) / 2.0)) if d.size else math.inf


def weighed_omega(sheet_omega: float, readings: Sequence[GainReading],
                  gain_weight: float | None = None) -> float:
    """The sheet's omega times the inverse-variance mean of the readings' ratios and the
    sheet's own (1 with :data:`PRODUCT_SLOPE_SCATTER`), within the plausible slopes.
    ``gain_weight``: the share of that ratio's move from 1 the product's units follow (the
    sheet's ``slope_gain_weight``, from its sample); None: all of it."""
    weights = [1.0 / PRODUCT_SLOPE_SCATTER**2]
    ratios = [1.0]
    for r in readings:
        sd = r.ratio_sd()
        if math.isfinite(sd) and math.isfinite(r.ratio()):
            weights.append(1.0 / sd**2)
            ratios.append(r.ratio())
    ratio = float(np.dot(weights, ratios) / np.sum(weights))
    if gain_weight is not None:
        ratio = 1.0 + float(gain_weight) * (ratio - 1.0)
    lo, hi = OMEGA_RANGE
    return min(max(sheet_omega * ratio, lo), hi)
