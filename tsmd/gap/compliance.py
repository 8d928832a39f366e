"""Tendon compliance from the protocol's reversals, against the catheter model's data sheet.

A tendon's stretch is a knob-angle offset proportional to its tension. After a reversal the
knob travels until the stretch and the tension the sheath's friction held are given back before
the tip moves back, so this lost motion grows with the current's swing at the reversal by an
amount per ampere that scales with the tendon's compliance. Slack and the joints' presliding
add a part that does not grow with the load; it cancels in the contrast of two loads: the
protocol's slow reversals at 40 deg (rate loops) against those at 60 deg (warm-up, dwells),
both knobs together, in every configuration. Each load's lost motion and swing are medians
over its repeats (one reversal carries the tracker noise, a dozen do not), and the repeats'
spread is the null.

Twice the compliance is, bit for bit, a catheter with half the tendon stiffness (docs/gap.md,
Limits): nothing inside the data tells "this unit's tendon is softer" from "this model's tendons
are soft", and another plant's simulator differs along that axis by more than the effect. So the
figure is compared with the same figure on the data sheet of the catheter model (measured on
another unit, :func:`reference_deg_per_A`); without one, compliance is not scored.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from tsmd.gap.data import GapSeries
from tsmd.gap.signature import SIGNATURES, SignatureScore

FloatArray = NDArray[np.float64]

MAX_SPEED_DEG_S = 45.0
"""Reversals at most this fast are read (the protocol's 20 and 40 deg/s): a fast reversal
passes the lost motion in a few samples and adds the current's viscous part to its swing."""
DEPARTURE_DEG = 1.5
"""The tip's return read between a third of this and this (5-15x the tracker noise)."""
SETTLE_DEG = 10.0
"""The current after the lost motion is read this far further on the releasing branch: by
then a sensor's lag of 0.1 s has caught up at the protocol's speeds (a lag is another effect)."""
PRE_WINDOW_S = 0.2
"""The current at a reversal: its mean over this long before it."""
TOLERANCE = 0.25
"""The data sheet's tolerance of the figure (a tendon lot's stiffness, the friction's share):
a unit is named more compliant only when the lower confidence bound of its ratio to the data
sheet exceeds 1 + this."""
TOGETHER_DEG = 2.0
"""Only reversals with the other knob at the same angle (the protocol moves both knobs
together in its warm-up, rate loops and dwells): the other knob's angle changes the load, and
coupling is another effect."""
LEVELS_DEG = (40.0, 60.0)
"""The two loads compared: reversals at the protocol's loop and dwell amplitudes (the
constant part of the lost motion, slack and the joints' presliding, cancels)."""
LEVEL_BAND_DEG = 2.0
MIN_PER_LEVEL = 3
CONDITION = "lost motion per ampere at the reversals against the data sheet"


@dataclass(frozen=True)
class Reversals:
    """Per slow reversal of one knob: lost motion (deg), current swing (A), configuration."""

    lost_deg: FloatArray
    swing_A: FloatArray
    config: NDArray[np.int64]
    at_deg: FloatArray
    """The knob angle of the reversal."""


def _reversal_pairs(x: FloatArray) -> list[tuple[int, int]]:
    """(last row moving the old way, first row moving the new way) at each reversal."""
    s = np.sign(np.round(np.diff(x), 9))
    moving = np.flatnonzero(s != 0)
    return [(int(a) + 1, int(b) + 1) for a, b in itertools.pairwise(moving)
            if s[a] != s[b]]


def _lost_motion(x: FloatArray, tip: FloatArray, a: int, b: int) -> tuple[float, int] | None:
    """Knob travel after the reversal at row ``a`` before the tip moves back, and the row
    :data:`SETTLE_DEG` of travel after it (None when the motion ends first). The tip's return
    between a third of :data:`DEPARTURE_DEG` and all of it is a line extrapolated back to no
    return, so neither the threshold nor the releasing branch's gain enters the figure."""
    direction = np.sign(x[b] - x[a])
    steps = np.sign(np.round(np.diff(x[b:]), 9))
    against = np.flatnonzero(steps == -direction)
    end = b + 1 + (int(against[0]) if against.size else len(steps))
    travel = np.abs(x[b:end] - x[a])
    ahead = direction * tip[max(a - 2, 0):end]
    moved = (ahead - np.minimum.accumulate(ahead))[b - max(a - 2, 0):]  # back from its extreme
    last = np.flatnonzero(moved >= DEPARTURE_DEG)
    if last.size == 0:
        return None
    # the return's start: after the last row below a third of the threshold before it (a
    # noise excursion within the lost motion does not start it; the running extreme of
    # dozens of noisy samples spreads by several standard deviations)
    below = np.flatnonzero(moved[:last[0]] < DEPARTURE_DEG / 3.0)
    if below.size == 0:
        return None
    first = int(below[-1]) + 1
    rows = slice(first, int(last[0]) + 1)
    if last[0] - first >= 2:
        slope, icept = np.polyfit(travel[rows], moved[rows], 1)
        lost = float(-icept / slope) if slope > 1e-6 else float(travel[first])
    else:
        lost = float(travel[first])
    settled = np.flatnonzero(travel >= lost + SETTLE_DEG)
    if settled.size == 0 or lost <= 0.0:
        return None
    return lost, b + int(settled[0])


def reversals(series: Sequence[GapSeries], knob: int) -> Reversals:
    """Every slow reversal of ``knob`` in the protocol recordings (the first of each recording
    left out: it starts from the straight catheter)."""
    configs = sorted({s.config for s in series})
    lost, swing, cfg, at = [], [], [], []
    for s in series:
        if s.segment is None:
            continue
        x, tip, cur, t = s.knob_deg[:, knob], s.tip_deg[:, knob], s.current_A[:, knob], s.t_s
        dt = float(np.median(np.diff(t)))
        pre = max(round(PRE_WINDOW_S / dt), 1)
        half = max(round(0.25 * PRE_WINDOW_S / dt), 1)
        for a, b in _reversal_pairs(x)[1:]:
            speed = max(abs(x[a] - x[a - 1]), abs(x[b] - x[a])) / dt
            other = s.knob_deg[a, 1 - knob]
            if a < pre or speed > MAX_SPEED_DEG_S or abs(other - x[a]) > TOGETHER_DEG:
                continue
            found = _lost_motion(x, tip, a, b)
            if found is None:
                continue
            i_rev = float(np.mean(cur[a - pre:a + 1]))
            i_dep = float(np.mean(cur[found[1] - half:found[1] + half + 1]))
            if abs(i_rev - i_dep) > 1e-4:
                lost.append(found[0])
                swing.append(abs(i_rev - i_dep))
                cfg.append(configs.index(s.config))
                at.append(float(x[a]))
    return Reversals(np.array(lost, dtype=float), np.array(swing, dtype=float),
                     np.array(cfg, dtype=np.int64), np.array(at, dtype=float))


def _levels(r: Reversals) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Reversals at the protocol's loop amplitude and at its dwell amplitude."""
    amp = np.abs(r.at_deg)
    return (np.abs(amp - LEVELS_DEG[0]) <= LEVEL_BAND_DEG,
            np.abs(amp - LEVELS_DEG[1]) <= LEVEL_BAND_DEG)


def _level_rows(r: Reversals) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    low, high = _levels(r)
    return np.flatnonzero(low), np.flatnonzero(high)


def _slope(r: Reversals, low: NDArray[np.int64], high: NDArray[np.int64]) -> float:
    """Extra lost motion per extra ampere from the low to the high load (medians: a reversal
    whose tip reading a noise spike ended early does not move it)."""
    d_swing = np.median(r.swing_A[high]) - np.median(r.swing_A[low])
    d_lost = np.median(r.lost_deg[high]) - np.median(r.lost_deg[low])
    return float(d_lost / d_swing) if d_swing > 0 else float("nan")


def _median_var(x: FloatArray) -> float:
    """Variance of a median from the spread between repeats (MAD, normal efficiency)."""
    mad = 1.4826 * float(np.median(np.abs(x - np.median(x))))
    return (1.2533 * mad) ** 2 / len(x)


def _log_slope_var(r: Reversals, low: NDArray[np.int64], high: NDArray[np.int64]) -> float:
    """Variance of log(:func:`_slope`) by the delta method."""
    d_swing = np.median(r.swing_A[high]) - np.median(r.swing_A[low])
    d_lost = np.median(r.lost_deg[high]) - np.median(r.lost_deg[low])
    v_lost = _median_var(r.lost_deg[high]) + _median_var(r.lost_deg[low])
    v_swing = _median_var(r.swing_A[high]) + _median_var(r.swing_A[low])
    return float(v_lost / d_lost ** 2 + v_swing / d_swing ** 2)


def lost_motion_per_A(series: Sequence[GapSeries]) -> tuple[float, float] | None:
    """The figure per knob (deg/A); None when a knob has fewer than
    :data:`MIN_PER_LEVEL` readable reversals at either load."""
    out = []
    for knob in (0, 1):
        r = reversals(series, knob)
        low, high = _level_rows(r)
        if min(len(low), len(high)) < MIN_PER_LEVEL:
            return None
        out.append(_slope(r, low, high))
    return out[0], out[1]


reference_deg_per_A = lost_motion_per_A
"""The data sheet's figure: the same estimator on the protocol recorded with another unit of
the catheter model (the manufacturer's bench, or the nominal unit of a simulated family)."""


def compliance_score(series: Sequence[GapSeries], reference: Sequence[float], n_tried: int,
                     family_alpha: float = 0.05, min_share: float = 0.05) -> SignatureScore | None:
    """Compliance named when the one-sided lower bound (level ``family_alpha / n_tried``; the
    null's spread from the repeats at each load) of the figure's ratio to ``reference`` (geometric
    mean over the knobs) exceeds 1 + :data:`TOLERANCE`. Share: the held-out shrink of the
    load contrast's excess over the data sheet's, the figure fitted on one configuration
    and scored on the other. None without enough readable reversals."""
    per_knob = [reversals(series, k) for k in (0, 1)]
    groups = [_level_rows(r) for r in per_knob]
    if any(min(len(g[0]), len(g[1])) < MIN_PER_LEVEL for g in groups):
        return None
    slopes = [_slope(r, low, high) for r, (low, high) in zip(per_knob, groups, strict=True)]
    if not all(np.isfinite(x) and x > 0.0 for x in slopes):
        return None
    log_ratio = float(np.mean(np.log(np.asarray(slopes) / np.asarray(reference))))
    se = 0.5 * float(np.sqrt(sum(_log_slope_var(r, *g)
                                 for r, g in zip(per_knob, groups, strict=True))))
    z_alpha = float(stats.norm.isf(family_alpha / max(n_tried, 1)))
    ratio, lower = float(np.exp(log_ratio)), float(np.exp(log_ratio - z_alpha * se))
    share, lo, hi = _heldout_shrink(per_knob, groups, reference)
    z = (log_ratio - np.log1p(TOLERANCE)) / se if se > 0 else float("nan")
    title, _ = SIGNATURES["compliance"]
    significant = bool(lower > 1.0 + TOLERANCE and share >= min_share)
    return SignatureScore("compliance", title, f"{CONDITION} (x{ratio:.2f}, lower bound "
                          f"x{lower:.2f})", share, (lo, hi), significant, share, 0.0,
                          float(np.clip(z, -40.0, 40.0)))


def _heldout_shrink(per_knob: Sequence[Reversals],
                    groups: Sequence[tuple[NDArray[np.int64], NDArray[np.int64]]],
                    reference: Sequence[float]) -> tuple[float, float, float]:
    """Mean, lowest and highest over held-out configurations of 1 - (the held-out load
    contrast's lost motion minus the figure fitted on the other configurations' times its
    current contrast)^2 / (the same with the data sheet's figure)^2, summed over the knobs;
    (0, nan, nan) with one configuration."""
    n_cfg = max(int(r.config.max()) + 1 for r in per_knob)
    shrinks = []
    for held in range(n_cfg):
        excess = resid = 0.0
        for r, (low, high), ref in zip(per_knob, groups, reference, strict=True):
            fit = (low[r.config[low] != held], high[r.config[high] != held])
            test = (low[r.config[low] == held], high[r.config[high] == held])
            if min(len(g) for g in (*fit, *test)) == 0:
                continue
            slope = _slope(r, *fit)
            d_lost = np.median(r.lost_deg[test[1]]) - np.median(r.lost_deg[test[0]])
            d_swing = np.median(r.swing_A[test[1]]) - np.median(r.swing_A[test[0]])
            if np.isfinite(slope):
                excess += float((d_lost - ref * d_swing) ** 2)
                resid += float((d_lost - slope * d_swing) ** 2)
        if excess > 0.0:
            shrinks.append(1.0 - resid / excess)
    if not shrinks:
        return 0.0, float("nan"), float("nan")
    return float(np.mean(shrinks)), min(shrinks), max(shrinks)
