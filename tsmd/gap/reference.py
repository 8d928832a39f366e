"""What a catheter model has always: its own rate dependence, coupling and creep, measured once.

A catheter's base physics may carry an effect of the catalogue by itself (the coilpipe plant's
relaxing tip and Stribeck friction give 0.3 deg of rate contrast on every unit, docs/gap.md
"Session 11"). A diagnosis that names every contrast names that on every unit of the model. The
protocol recorded on the data sheet's unit (with the tracker, as the compliance data sheet is)
gives the model's own contrasts of the *measured* signals, independent of any simulator; a unit
is then compared with it: the residual's contrast plus the simulator's own contrast (the
measured minus the residual's, on the same rows) minus the reference's is what this unit has
beyond its model. A unit scatters around its model's reference: measured on several units
(session 13), the reference is their mean and their spread about it counts as noise, as the
reference's own repeat noise does, before the size rule (one sample's tracker or current noise)
is applied; from one unit the spread is unknown and counts as 0 (session 12).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.compliance import ComplianceSheet
from tsmd.gap.data import GapSeries
from tsmd.gap.dwell import CURRENT_COLUMNS, Drift
from tsmd.gap.loops import Loops, contrast_of

FloatArray = NDArray[np.float64]

REFERENCED: tuple[str, ...] = ("rate", "coupling")
"""Loop tests compared with the model's reference. Curvature is not: its levels are the
session's own configurations, which a reference unit recorded elsewhere does not share."""


@dataclass(frozen=True)
class LoopReference:
    """One loop test's level contrast on the reference unit, per point of its loops."""

    levels: tuple[str, ...]
    value: FloatArray  # (levels, K) contrast of the measured signal, mean over configurations
    knob_deg: FloatArray  # (K,)
    dirn: FloatArray  # (K,)
    part: FloatArray  # (K,)
    noise_per_point: float
    """Expected squared contrast per point from the reference's repeat noise alone."""
    scatter_per_point: float = 0.0
    """Squared contrast per point (summed over the levels, as ``noise_per_point``) a unit of
    the model may lie from the reference: the reference units' spread about their mean as a
    95 % prediction bound (0 from one unit)."""

    def at(self, lp: Loops, levels: Sequence[str]) -> FloatArray | None:
        """The reference contrast at ``lp``'s points (levels in ``levels``' order), or None
        when the levels differ."""
        if sorted(levels) != sorted(self.levels):
            return None
        x = lp.knob * lp.span_deg
        out = np.zeros((len(levels), len(x)))
        for p in np.unique(lp.part):
            for d in (-1.0, 1.0):
                mine = (lp.part == p) & (lp.dirn == d)
                ref = (self.part == p) & (self.dirn == d)
                if not mine.any():
                    continue
                if ref.sum() < 2:
                    return None
                order = np.argsort(self.knob_deg[ref])
                for i, lv in enumerate(levels):
                    row = self.value[self.levels.index(lv)][ref][order]
                    out[i, mine] = np.interp(x[mine], self.knob_deg[ref][order], row)
        return out


@dataclass(frozen=True)
class ProductReference:
    """The model's own contrasts (its 'always'), from the protocol on the data sheet's unit."""

    loops: dict[str, LoopReference]
    creep: tuple[FloatArray, FloatArray] | None = None
    """Per dwell pair and current, the loaded-minus-unloaded slope (A/s), mean over
    configurations and units, and the variance a unit's slope has about it (the mean's noise
    plus the units' spread)."""
    units: int = 1
    """How many catheters of the model the reference was measured on."""
    compliance: ComplianceSheet | None = None
    """The model's lost motion per ampere from the same units, with its noise and the units'
    spread (session 14): the compliance test's data sheet when present."""
    currents: LoopReference | None = None
    """The rate test's fast-slow contrast of the measured currents (session 16): what the
    sensor-lag test compares a unit with."""


def measured_windows(s: GapSeries) -> FloatArray:
    """A series' measured channels laid out as a residual (tip 1, tip 2, current 1, 2)."""
    return np.column_stack([s.tip_deg, s.current_A])


def beyond_reference(res: Loops, meas: Loops, levels: Sequence[str],
                     ref: LoopReference | None) -> Loops:
    """The residual loops less the model's own contrast: ``res`` plus the simulator's own
    contrast (``meas`` - ``res``, the same rows) minus the reference's, scaled down to what
    the unit has of it when that is less (:func:`own_scale`), knob by knob (since session 16:
    one scale for both knobs counted a unit's shortfall on one knob as an excess on the other;
    helixbelt development unit 1 reads 0.71 and 1.48 of its model's contrast on the two).
    Unchanged without a reference or when the levels do not match."""
    if ref is None:
        return res
    own = ref.at(res, levels)
    if own is None or meas.y.shape != res.y.shape:
        return res
    measured = contrast_of(meas)
    sim = measured - contrast_of(res)
    scale = np.ones(res.part.shape)
    for p in np.unique(res.part):  # each knob's tendon and lumen scatter on their own
        mine = res.part == p
        scale[mine] = own_scale(measured[:, mine], own[:, mine])
    y = res.y + (sim - scale * own)[:, None, :]
    per_point = ref.noise_per_point + ref.scatter_per_point
    return replace(res, y=y, ref_noise_ss=res.y.shape[2] * per_point)


def own_scale(measured: FloatArray, own: FloatArray) -> float:
    """How much of its model's own contrast a unit's measured contrast has (its projection on
    the reference's), at most all of it: a unit with less of the model's own contrast than the
    model has no effect added along it. A twistshaft unit with its tendons halved keeps 0.5-0.7
    of its model's coupling contrast, and the rest, counted beyond the reference, was named
    coupling (docs/gap.md "Session 14"); an added coupling has 2.3-3 times the model's."""
    norm = float((own * own).sum())
    if norm <= 0.0:
        return 1.0
    return float(np.clip((measured * own).sum() / norm, 0.0, 1.0))


ONE_SIDED_CREEP = True
"""When True (since session 26), the currents' drift beyond the model's own is read one-sided,
as the tips' is (:func:`tsmd.gap.dwell.tip_relaxation`): only a held knob's current relaxing
*faster* than the model's units' is creep. A unit whose current relaxes more slowly (a softer
rope in front of a section that relaxes: the blind pronyring plant's compliance case, docs/gap.md
"Session 26") does not creep more. Switched on after every plant's creep and "none" cases kept
their verdicts with it (docs/gap.md "Session 26", "Round 2"); False is the two-sided reading."""


def drift_beyond_reference(res: Drift, meas: Drift,
                           creep: tuple[FloatArray, FloatArray] | None) -> Drift:
    """The residual's dwell slopes less the model's own: the measured slopes minus the
    reference's, pair by pair, their variances added (with :data:`ONE_SIDED_CREEP`, the
    currents' part toward a smaller load only, else 0). Unchanged without a reference or when
    the dwells differ."""
    if creep is None or not (meas.diff.shape == res.diff.shape == creep[0].shape):
        return res
    own, own_var = creep
    beyond = meas.diff - own
    if ONE_SIDED_CREEP and meas.load_sign is not None:
        currents = beyond[:, CURRENT_COLUMNS]
        beyond[:, CURRENT_COLUMNS] = np.maximum(-meas.load_sign * currents, 0.0)
    return Drift(beyond, res.var + own_var, res.span_s)

