"""Tendon compliance from the protocol's reversals, against the catheter model's data sheet.

A tendon's stretch is a knob-angle offset proportional to its tension. After a reversal the
knob travels until the stretch and the tension the sheath's friction held are given back before
the tip moves back, so this lost motion grows with the current's swing at the reversal by an
amount per ampere that scales with the tendon's compliance. Slack and the joints' presliding
add a part that does not grow with the load; it cancels in the contrast of two loads: the
protocol's slow reversals at 40 deg (rate loops) against those at 60 deg (warm-up, dwells),
both knobs together, in every configuration, each side of the knob on its own. Each load's lost
motion is read from the mean of its repeats' return curves (the tracker noise averaged before a
threshold is applied to it), and the null's spread is the repeats' own: a jackknife over them.
When the data sheet's units break that premise (a geared handle's play crossed before the tip
returns from the lighter load only), every unit is read on the release at the heavier load
instead: the knob travel per ampere over which the motor current gives the load back.

Twice the compliance is, bit for bit, a catheter with half the tendon stiffness (docs/gap.md,
Limits): nothing inside the data tells "this unit's tendon is softer" from "this model's tendons
are soft", and another plant's simulator differs along that axis by more than the effect. So the
figure is compared with the same figure on the data sheet of the catheter model (measured on
another unit, :func:`reference_deg_per_A`); without one, compliance is not scored.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from tsmd.gap.data import GapSeries
from tsmd.gap.protocol import ProtocolDesign
from tsmd.gap.reversal import TRAVEL_GRID_DEG, Reversals, reversals
from tsmd.gap.signature import SIGNATURES, SignatureScore
from tsmd.gap.stats import unit_spread

FloatArray = NDArray[np.float64]

DEPARTURE_DEG = 1.5
"""The mean return curve read between a third of this and this (or of 0.6 of the curve's full
return when that is smaller: a soft tendon at the loop amplitude leaves the tip barely out of
its dead zone)."""
MIN_RETURN_DEG = 0.3
"""A mean return read below this is no return (the tracker noise of one reversal is 0.1 deg)."""
SETTLE_WINDOW_DEG = 2.0
"""The current after the lost motion: its mean over this much travel either side."""
SETTLE_DEG = 10.0
"""The current after the lost motion is read this far further on the releasing branch: by
then a sensor's lag of 0.1 s has caught up at the protocol's speeds (a lag is another effect)."""
TOLERANCE = 0.25
"""The smallest excess named: a unit is named more compliant only when its ratio to the data
sheet is at least 1 + this; from a sheet of one unit (spread unknown) its lower confidence
bound must exceed it too (:func:`compliance_score`)."""
LEVELS_DEG = (ProtocolDesign.amp_deg, ProtocolDesign.dwell_amp_deg)
"""The two loads compared: reversals at the protocol's loop and dwell amplitudes (the
constant part of the lost motion, slack and the joints' presliding, cancels); taken from the
protocol's design, so that moving its dwells moves the figure's heavier load with them."""
CONTRAST_LEVELS_DEG = LEVELS_DEG
"""The two loads of the load contrast. :data:`LEVELS_DEG` unless the protocol adds a heavier
load (``ProtocolDesign.heavy_amp_deg``): then the light load against it, while the premise
(:func:`load_growth`) and the release stay on :data:`LEVELS_DEG`, where a geared handle's play
shows (with the heavy load alone the premise no longer fires on warmgear, and its release at 75
deg scatters more: docs/gap.md "Session 26"). Off by default: (40, 60)."""
LEVEL_BAND_DEG = 2.0
MIN_PER_LEVEL = 3
"""Repeats at each load and side for a figure (the jackknife needs a few)."""
RELEASE_SHARES = (0.75, 0.25)
"""The current's release after a reversal read between these shares of the way from its level
before the reversal to its release level: above, the first sample's step (the handle's and the
motor's friction turning over); below, the approach to the release level."""
Figure = Literal["load contrast", "release"]
"""How the lost motion per ampere is read: across the two loads' reversals (the default), or
within the release of the reversals beyond the slack (:func:`sheet_from_units` decides)."""
CONDITION = "lost motion per ampere at the reversals against the data sheet"


def _onset(curve: FloatArray) -> float:
    """Knob travel before the mean return curve leaves zero: the line through its rise between
    a third of the threshold and the threshold, extrapolated back to no return (neither the
    threshold nor the releasing branch's gain enters); NaN without a readable return."""
    top = float(np.nanmax(curve)) if np.isfinite(curve).any() else 0.0
    high = min(DEPARTURE_DEG, 0.6 * top)
    if high < MIN_RETURN_DEG:
        return float("nan")
    above = np.flatnonzero(curve >= high)
    below = np.flatnonzero(curve[:above[0]] < high / 3.0)
    if below.size == 0:
        return float("nan")
    rows = slice(int(below[-1]) + 1, int(above[0]) + 1)
    if above[0] - below[-1] >= 3:
        slope, icept = np.polyfit(TRAVEL_GRID_DEG[rows], curve[rows], 1)
        if slope > 1e-6:
            return float(-icept / slope)
    return float(TRAVEL_GRID_DEG[rows.start])


def _group(r: Reversals, rows: NDArray[np.int64]) -> tuple[float, float]:
    """Lost motion (deg) of the repeats' mean return curve, and their mean current swing (A):
    the current before the reversal minus the current :data:`SETTLE_DEG` of travel after the
    lost motion (by then a sensor's lag of 0.1 s has caught up at the protocol's speeds)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # columns beyond every motion
        lost = _onset(np.nanmean(r.tip_return_deg[rows], axis=0))
        if not np.isfinite(lost):
            return float("nan"), float("nan")
        near = np.abs(TRAVEL_GRID_DEG - lost - SETTLE_DEG) <= SETTLE_WINDOW_DEG
        after = np.nanmean(r.current_A[np.ix_(rows, np.flatnonzero(near))], axis=1)
        swing = np.abs(r.before_A[rows] - after)
        return lost, float(np.nanmean(swing)) if np.isfinite(swing).any() else float("nan")


def _release(r: Reversals, rows: NDArray[np.int64]) -> tuple[float, float]:
    """Knob travel (deg) over which the repeats' mean current gives back the middle half of
    its load (:data:`RELEASE_SHARES`), and that load (A): the mean current before the reversal
    minus its release level, the mean over :data:`SETTLE_DEG` +- :data:`SETTLE_WINDOW_DEG` of
    travel. The motor feels the tendon and the handle's gear unload along the travel whatever
    the load, so no constant part (slack, a gear's play) enters."""
    side = float(np.sign(np.mean(r.at_deg[rows])))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # columns beyond every motion
        y = side * np.nanmean(r.current_A[rows], axis=0)
        settled = np.abs(TRAVEL_GRID_DEG - SETTLE_DEG) <= SETTLE_WINDOW_DEG
        level = float(np.nanmean(y[settled]))
    load = float(side * np.mean(r.before_A[rows])) - level
    if not (np.isfinite(load) and load > 0.0):
        return float("nan"), float("nan")
    at = []
    for share in RELEASE_SHARES:
        below = np.flatnonzero(y[1:] < level + share * load) + 1
        if below.size == 0:
            return float("nan"), float("nan")
        k = int(below[0])
        at.append(float(np.interp(level + share * load, [y[k], y[k - 1]],
                                  [TRAVEL_GRID_DEG[k], TRAVEL_GRID_DEG[k - 1]])))
    return at[1] - at[0], (RELEASE_SHARES[0] - RELEASE_SHARES[1]) * load


def _jackknife_var(r: Reversals, rows: NDArray[np.int64],
                   read: Callable[[Reversals, NDArray[np.int64]], tuple[float, float]] = _group
                   ) -> tuple[float, float]:
    """Variance of a group's two figures (:func:`_group`'s or :func:`_release`'s) from its
    repeats (leave one out)."""
    n = len(rows)
    loo = np.array([read(r, np.delete(rows, i)) for i in range(n)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        dev = loo - np.nanmean(loo, axis=0)
        var = (n - 1) / n * np.nansum(dev ** 2, axis=0)
    return float(var[0]), float(var[1])


@dataclass(frozen=True)
class Contrast:
    """High load minus low load, summed over the knob's sides: lost motion (deg), current
    swing (A) and their variances."""

    lost_deg: float
    swing_A: float
    var_lost: float = 0.0
    var_swing: float = 0.0

    @property
    def slope(self) -> float:
        """Extra lost motion per extra ampere (deg/A)."""
        return self.lost_deg / self.swing_A if self.swing_A > 0.0 else float("nan")

    @property
    def log_var(self) -> float:
        """Variance of log(:attr:`slope`) by the delta method."""
        return self.var_lost / self.lost_deg ** 2 + self.var_swing / self.swing_A ** 2


def _contrast(r: Reversals, rows: NDArray[np.int64], with_var: bool = False,
              min_per_group: int = 1, figure: Figure = "load contrast",
              loads_deg: tuple[float, float] | None = None) -> Contrast | None:
    """The load contrast over ``rows`` (at ``loads_deg``, default :data:`CONTRAST_LEVELS_DEG`):
    per side of the knob (its two sides differ in slack and in how far the loop leaves the dead
    zone), sides readable at both loads. With ``figure`` "release", per side the release travel
    and load at the higher load alone."""
    amp = np.abs(r.at_deg[rows])
    side = np.sign(r.at_deg[rows])
    total = np.zeros(4)
    found = False
    levels = LEVELS_DEG if figure == "release" else loads_deg or CONTRAST_LEVELS_DEG
    for s in (1.0, -1.0):
        groups = [rows[(np.abs(amp - level) <= LEVEL_BAND_DEG) & (side == s)]
                  for level in levels]
        if min(len(g) for g in groups) < min_per_group:
            continue
        if figure == "release":
            travel, load = _release(r, groups[-1])
            if not np.isfinite([travel, load]).all():
                continue
            spread = _jackknife_var(r, groups[-1], _release) if with_var else (0.0, 0.0)
            total += (travel, load, *spread)
            found = True
            continue
        (lost_lo, swing_lo), (lost_hi, swing_hi) = (_group(r, g) for g in groups)
        if not np.isfinite([lost_lo, swing_lo, lost_hi, swing_hi]).all():
            continue
        var = ([sum(v) for v in zip(*(_jackknife_var(r, g) for g in groups), strict=True)]
               if with_var else [0.0, 0.0])
        total += (lost_hi - lost_lo, swing_hi - swing_lo, *var)
        found = True
    return Contrast(*(float(v) for v in total)) if found else None


def _figures(series: Sequence[GapSeries], figure: Figure = "load contrast",
             loads_deg: tuple[float, float] | None = None
             ) -> list[tuple[Reversals, Contrast] | None]:
    """Per knob its reversals and load contrast; None for a knob without a readable one (a
    soft tendon can leave the tip inside its dead zone at the loop amplitude)."""
    out: list[tuple[Reversals, Contrast] | None] = []
    for knob in (0, 1):
        r = reversals(series, knob)
        c = _contrast(r, np.arange(len(r.at_deg)), with_var=True, min_per_group=MIN_PER_LEVEL,
                      figure=figure, loads_deg=loads_deg)
        ok = c is not None and np.isfinite(c.slope) and c.slope > 0.0
        out.append((r, c) if ok and c is not None else None)
    return out


def load_growth(series: Sequence[GapSeries]) -> list[tuple[float, float]]:
    """Per side of each knob read at both loads: how much later the tip returns from the
    higher load (deg) and that figure's variance (the repeats' jackknife). The load contrast's
    premise is that it is positive (the constant part cancels). At a light load a released
    section can be too weak to pull its tendon, and a geared handle's drum, back through the
    gear's play against the drum's friction; the knob then crosses the play before the tip
    returns, a constant part the higher load does not have (warmgear, docs/gap.md "Session
    19")."""
    out = []
    for knob in (0, 1):
        r = reversals(series, knob)
        amp, side = np.abs(r.at_deg), np.sign(r.at_deg)
        for s in (1.0, -1.0):
            groups = [np.flatnonzero((np.abs(amp - level) <= LEVEL_BAND_DEG) & (side == s))
                      for level in LEVELS_DEG]
            if min(len(g) for g in groups) < MIN_PER_LEVEL:
                continue
            lost_lo, lost_hi = (_group(r, g)[0] for g in groups)
            if np.isfinite([lost_lo, lost_hi]).all():
                out.append((lost_hi - lost_lo, sum(_jackknife_var(r, g)[0] for g in groups)))
    return out


def premise_holds(units: Sequence[Sequence[GapSeries]], family_alpha: float = 0.05) -> bool:
    """False when some side of some unit returns sooner from the higher load beyond its noise
    (one-sided, level ``family_alpha`` over all the sides tested: a side that merely does not
    grow, coilpipe's unit 5 knob 1, is noise about a small contrast)."""
    growth = [g for u in units for g in load_growth(u)]
    if not growth:
        return True
    z_alpha = float(stats.norm.isf(family_alpha / len(growth)))
    return all(d >= -z_alpha * np.sqrt(v) for d, v in growth)


def lost_motion_per_A(series: Sequence[GapSeries]) -> tuple[float, float] | None:
    """The figure per knob (deg/A); None when a knob has no side with :data:`MIN_PER_LEVEL`
    readable reversals at both loads."""
    found = _figures(series)
    if found[0] is None or found[1] is None:
        return None
    return found[0][1].slope, found[1][1].slope


reference_deg_per_A = lost_motion_per_A
"""The data sheet's figure: the same estimator on the protocol recorded with another unit of
the catheter model (the manufacturer's bench, or the nominal unit of a simulated family)."""


@dataclass(frozen=True)
class ComplianceSheet:
    """The model's figure per knob (deg/A; NaN: no unit read it), the log variance of that
    figure's noise, and the log variance a further unit may lie from it (a one-sided 95 %
    prediction bound from the units' spread beyond their own noise; 0 from one unit). A figure
    from one unit scatters like any unit (twistshaft unit 0 reads 0.8-0.9 of its units'
    centre), so a sheet from several units is the centre a unit is compared with."""

    figure_deg_per_A: tuple[float, float]
    noise_log_var: tuple[float, float] = (0.0, 0.0)
    allowance_log_var: tuple[float, float] = (0.0, 0.0)
    units: int = 1
    """How many units the sheet was measured on: from one, the units' spread is unknown."""
    figure: Figure = "load contrast"
    """How the figure is read, on the sheet's units and on the unit compared with it."""
    loads_deg: tuple[float, float] | None = None
    """The two loads of the load contrast, on the sheet's units and on the unit compared with
    it (None: :data:`CONTRAST_LEVELS_DEG`; :mod:`tsmd.gap.compliance_pairs` chooses)."""


def sheet_from_units(units: Sequence[Sequence[GapSeries]], family_alpha: float = 0.05,
                     loads_deg: tuple[float, float] | None = None) -> ComplianceSheet | None:
    """The sheet from the protocol of each of several units (one list of series per unit):
    per knob the mean over the units that read it of the log figure, that mean's noise and the
    units' spread (:func:`tsmd.gap.stats.unit_spread`); None when no unit reads either knob.
    The figure is the load contrast unless the units break its premise (:func:`premise_holds`);
    then it is the release at the higher load, on every unit (since session 19: warmgear's
    reference units read 41-159 deg/A by the load contrast, 58-81 by the release)."""
    kind: Figure = "load contrast" if premise_holds(units, family_alpha) else "release"
    per_unit = [_figures(u, kind, loads_deg) for u in units]
    figure, noise, allowance = [], [], []
    for knob in (0, 1):
        read = [found[1] for f in per_unit if (found := f[knob]) is not None]
        if not read:
            figure.append(float("nan"))
            noise.append(0.0)
            allowance.append(0.0)
            continue
        mean, own, spread = unit_spread(np.array([[np.log(c.slope)] for c in read]),
                                        np.array([[c.log_var] for c in read]))
        figure.append(float(np.exp(mean[0])))
        noise.append(float(own[0]))
        allowance.append(float(spread[0]))
    if not np.isfinite(figure).any():
        return None
    return ComplianceSheet((figure[0], figure[1]), (noise[0], noise[1]),
                           (allowance[0], allowance[1]), len(units), kind, loads_deg)


def compliance_score(series: Sequence[GapSeries], reference: Sequence[float] | ComplianceSheet,
                     n_tried: int, family_alpha: float = 0.05,
                     min_share: float = 0.05) -> SignatureScore | None:
    """Compliance named when the figure's ratio to the sheet (knobs combined by
    :func:`knobs_combined`) is at least 1 + :data:`TOLERANCE` and its one-sided lower bound
    (level ``family_alpha / n_tried``; the null's spread from the repeats at each load, a
    jackknife, and the sheet's own noise) lies beyond the units' spread
    (the sheet's allowance), every knob read above the sheet (one lot of tendons moves both
    knobs' figures alike). From one unit the spread is unknown and the lower bound must
    exceed 1 + :data:`TOLERANCE` itself. Since session 15 the tolerance is a smallest size on
    the figure, not added to a measured spread (that counted the spread twice: stickslip's
    halved tendons read x1.4-1.6 and were missed). Share: the
    held-out shrink of the load contrast's excess over the sheet's, the figure fitted on one
    configuration and scored on the other. None when no knob has enough readable reversals.
    The unit's figure is read as the sheet's was (:attr:`ComplianceSheet.figure`)."""
    sheet = (reference if isinstance(reference, ComplianceSheet)
             else ComplianceSheet((float(reference[0]), float(reference[1]))))
    per_knob = _figures(series, sheet.figure, sheet.loads_deg)
    found = [(f, ref, nv, av) for f, ref, nv, av in zip(
        per_knob, sheet.figure_deg_per_A, sheet.noise_log_var, sheet.allowance_log_var,
        strict=True) if f is not None and np.isfinite(ref) and ref > 0.0]
    if not found:
        return None
    slopes = np.array([c.slope for (_, c), _, _, _ in found])
    refs = np.array([ref for _, ref, _, _ in found])
    per_knob_log = np.log(slopes / refs)
    log_ratio, se, weight = knobs_combined(
        per_knob_log, np.array([c.log_var + nv for (_, c), _, nv, _ in found]))
    # a unit's constants move both knobs' figures together: the allowances' weighted mean,
    # not their average's shrunken spread
    allowance = (float(weight @ np.sqrt([av for _, _, _, av in found])) if sheet.units > 1
                 else float(np.log1p(TOLERANCE)))
    z_alpha = float(stats.norm.isf(family_alpha / max(n_tried, 1)))
    ratio, lower = float(np.exp(log_ratio)), float(np.exp(log_ratio - z_alpha * se))
    share, lo, hi = _heldout_shrink([r for (r, _), _, _, _ in found], list(refs),
                                    sheet.figure, sheet.loads_deg)
    z = (log_ratio - allowance) / se if se > 0 else float("nan")
    title, _ = SIGNATURES["compliance"]
    # a unit's tendons are one lot: a softer one raises every knob's figure, and one precise
    # knob far up while the other reads below the sheet is one figure's scatter
    significant = bool(lower > np.exp(allowance) and log_ratio > np.log1p(TOLERANCE)
                       and bool((per_knob_log > 0.0).all()) and share >= min_share)
    how = (", read on the release" if sheet.figure == "release" else "" if sheet.loads_deg is None
           else f", loads {sheet.loads_deg[0]:g}/{sheet.loads_deg[1]:g} deg")
    return SignatureScore("compliance", title, f"{CONDITION}{how} (x{ratio:.2f}, lower bound "
                          f"x{lower:.2f} against the units' spread x{np.exp(allowance):.2f}, "
                          f"the smallest named x{1.0 + TOLERANCE:.2f})", share, (lo, hi),
                          significant, share, 0.0, float(np.clip(z, -40.0, 40.0)))


def knobs_combined(log_ratio: FloatArray, log_var: FloatArray
                   ) -> tuple[float, float, FloatArray]:
    """The knobs' figures combined: their mean log ratio weighted by precision (one knob's tip
    barely out of its dead zone reads a figure ten times as noisy as the other's), its
    standard error and the weights."""
    w = 1.0 / np.maximum(log_var, 1e-12)
    w /= w.sum()
    return float(w @ log_ratio), float(np.sqrt(w ** 2 @ log_var)), w


def _heldout_shrink(per_knob: Sequence[Reversals], reference: Sequence[float],
                    figure: Figure = "load contrast",
                    loads_deg: tuple[float, float] | None = None) -> tuple[float, float, float]:
    """Mean, lowest and highest over held-out configurations of 1 - (the held-out load
    contrast's lost motion minus the figure fitted on the other configurations times its
    current contrast)^2 / (the same with the data sheet's figure)^2, summed over the knobs;
    (0, nan, nan) with one configuration. With ``figure`` "release", the release travel
    against its load in place of the load contrast."""
    n_cfg = max(int(r.config.max()) + 1 if len(r.config) else 0 for r in per_knob)
    shrinks = []
    for held in range(n_cfg):
        excess = resid = 0.0
        for r, ref in zip(per_knob, reference, strict=True):
            fit = _contrast(r, np.flatnonzero(r.config != held), figure=figure,
                            loads_deg=loads_deg)
            test = _contrast(r, np.flatnonzero(r.config == held), figure=figure,
                             loads_deg=loads_deg)
            if fit is None or test is None or not np.isfinite(fit.slope):
                continue
            excess += (test.lost_deg - ref * test.swing_A) ** 2
            resid += (test.lost_deg - fit.slope * test.swing_A) ** 2
        if excess > 0.0:
            shrinks.append(1.0 - resid / excess)
    if not shrinks:
        return 0.0, float("nan"), float("nan")
    return float(np.mean(shrinks)), min(shrinks), max(shrinks)
