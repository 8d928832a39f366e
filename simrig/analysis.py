"""Ground truth from a sweep: dead zone, backlash and slope measured on the tip angle.

These helpers look only at the knob and tip arrays of a sweep (the EM tracker's view), never at
plant parameters, so they measure what a catheter actually does. Definitions follow the paper's
piecewise-linear model (see ``docs/plant.md``):

- ``dead_zone_pos_deg`` (``D_pos``): on a rising pass, the knob angle at which the tip leaves the
  dead-zone plateau upwards (rises more than ``threshold_deg`` above the line the plateau
  follows: flat on a still plateau, sloped on one the tip creeps along).
- ``dead_zone_neg_deg`` (``D_neg``, signed, normally negative): the same on a falling pass.
- ``backlash_pos_deg`` (``B_pos``): knob travel after a reversal at the positive extreme before the
  tip has moved back by ``threshold_deg``.
- ``backlash_neg_deg`` (``B_neg``): the same after a reversal at the negative extreme.

Each value is the median over all complete passes (a pass runs from one reversal to the next;
the stretch before the first reversal is ignored).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import minimize

FloatArray = NDArray[np.float64]


class DeadZoneBacklash(NamedTuple):
    """Dead zone and backlash of one knob, knob degrees (``D_neg`` signed)."""

    dead_zone_pos_deg: float
    dead_zone_neg_deg: float
    backlash_pos_deg: float
    backlash_neg_deg: float


class SweepAnalysisError(ValueError):
    """The arrays do not hold a sweep these measures are defined on."""


def split_passes(knob_deg: ArrayLike) -> list[tuple[int, int, int]]:
    """Monotone passes of a sweep as ``(start, stop, direction)`` index ranges.

    A pass starts at a reversal and ends at the next one (the stretches before the first and
    after the last reversal are dropped: they need not span the range); samples where the knob
    does not move belong to the pass they interrupt.
    """
    q = np.asarray(knob_deg, dtype=np.float64)
    dq = np.diff(q)
    moving = np.flatnonzero(dq != 0.0)
    if moving.size == 0:
        return []
    direction = np.sign(dq[moving])
    turns = np.flatnonzero(direction[1:] != direction[:-1])
    # Reversal sample = the last sample of the previous direction (the extreme).
    edges = [int(moving[i] + 1) for i in turns]
    passes = []
    for a, b in itertools.pairwise(edges):
        passes.append((a, b + 1, int(np.sign(q[b] - q[a]))))
    return [p for p in passes if p[1] - p[0] >= 3 and p[2] != 0]


def _rising_pass_measures(q: FloatArray, tip: FloatArray, thr: float) -> tuple[float, float]:
    """(backlash, dead zone edge) of a pass with the knob increasing."""
    rising_max = np.maximum.accumulate(tip)
    start = tip[0]
    left = np.flatnonzero(rising_max > start + thr)
    if left.size == 0:
        return float("nan"), float("nan")
    i_left = int(left[0])
    backlash = float(q[i_left] - q[0])
    # Dead-zone plateau: the stretch from which the knob must travel farthest before the tip
    # rises by the threshold. The dead zone ends where the tip has risen the threshold above
    # the line the plateau follows (see _plateau_line), searched from the stretch's middle.
    qs = q[i_left:]
    cm = rising_max[i_left:]
    ts = tip[i_left:]
    j = np.searchsorted(cm, ts + thr, side="right")
    valid = j < qs.size
    if not np.any(valid):
        return backlash, float("nan")
    travel = np.where(valid, qs[np.minimum(j, qs.size - 1)] - qs, -np.inf)
    i_best = int(np.argmax(travel))
    q_a, q_b = float(qs[i_best]), float(qs[j[i_best]])
    slope, level = _plateau_line(qs, ts, q_a, q_b)
    mid = int(np.searchsorted(qs, 0.5 * (q_a + q_b)))
    off_line = ts[mid:] - (level + slope * (qs[mid:] - 0.5 * (q_a + q_b)))
    above = np.flatnonzero(off_line > thr)
    if above.size == 0:
        return backlash, float("nan")
    return backlash, float(qs[mid + above[0]])


def _plateau_line(qs: FloatArray, ts: FloatArray, q_a: float, q_b: float) -> tuple[float, float]:
    """(slope, level at the stretch's middle) of the line the tip follows along the plateau
    stretch ``q_a..q_b``: a least-squares line over the stretch's middle half (so neither a
    start just below the plateau nor the rise at its end biases it). The tip "starts to move"
    where it leaves this line: a tip creeping along its plateau (a coil settling, a sheath
    sliding) is not yet pulled by the tendon, and measured against a flat median level it would
    cross the threshold mid-plateau (session 20: 10-17 deg early beyond ~0.07 deg/deg). A flat
    plateau gives a flat line, so its reading is the median level's. Too few samples: flat, at
    the median of the stretch."""
    middle = (qs >= q_a + 0.25 * (q_b - q_a)) & (qs <= q_a + 0.75 * (q_b - q_a))
    q_mid = 0.5 * (q_a + q_b)
    if np.count_nonzero(middle) >= 3 and np.ptp(qs[middle]) > 0.0:
        slope, level = np.polyfit(qs[middle] - q_mid, ts[middle], 1)
        return float(slope), float(level)
    stretch = (qs >= q_a) & (qs <= q_b)
    return 0.0, float(np.median(ts[stretch]))


def measure_dead_zone_backlash(
    knob_deg: ArrayLike, tip_deg: ArrayLike, threshold_deg: float = 1.0
) -> DeadZoneBacklash:
    """Measure ``D_pos, D_neg, B_pos, B_neg`` (knob degrees) from a sweep's tip angle.

    ``knob_deg`` is the actual knob angle and ``tip_deg`` the tip angle (true or tracked) of a
    periodic sweep through both dead-zone edges; at least one complete pass each way is needed.
    ``threshold_deg`` is the tip motion that counts as "the tip moves": above the tracker noise,
    small against the loaded slope. NaN marks a quantity that never occurred (no plateau).
    """
    q = np.asarray(knob_deg, dtype=np.float64)
    y = np.asarray(tip_deg, dtype=np.float64)
    if q.ndim != 1 or q.shape != y.shape:
        raise SweepAnalysisError(
            f"knob_deg and tip_deg must be 1-D arrays of one length, got {q.shape} and {y.shape}"
        )
    if not threshold_deg > 0.0:
        raise SweepAnalysisError(f"threshold_deg must be > 0, got {threshold_deg!r}")
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(y))):
        raise SweepAnalysisError("knob_deg and tip_deg must be finite (drop NaN samples first)")
    return _over_passes(q, y, threshold_deg, _rising_pass_measures)


PassReading = Callable[[FloatArray, FloatArray, float], tuple[float, float]]
"""(backlash, dead zone edge) of one rising pass (a falling one is read mirrored)."""


def _over_passes(q: FloatArray, y: FloatArray, threshold_deg: float,
                 per_pass: PassReading) -> DeadZoneBacklash:
    """Each pass read by ``per_pass`` (falling ones mirrored), the median over passes."""
    up: list[tuple[float, float]] = []
    down: list[tuple[float, float]] = []
    for a, b, direction in split_passes(q):
        if direction > 0:
            up.append(per_pass(q[a:b], y[a:b], threshold_deg))
        else:
            bl, dz = per_pass(-q[a:b], -y[a:b], threshold_deg)
            down.append((bl, -dz))
    if not up or not down:
        raise SweepAnalysisError("need at least one complete rising and one falling pass")
    b_neg, d_pos = np.nanmedian(np.array(up), axis=0) if _finite(up) else (np.nan, np.nan)
    b_pos, d_neg = np.nanmedian(np.array(down), axis=0) if _finite(down) else (np.nan, np.nan)
    return DeadZoneBacklash(float(d_pos), float(d_neg), float(b_pos), float(b_neg))


def _finite(rows: list[tuple[float, float]]) -> bool:
    return bool(np.any(np.isfinite(np.array(rows))))


def loaded_slope(
    knob_deg: ArrayLike, tip_deg: ArrayLike, lo_deg: float, hi_deg: float
) -> tuple[float, float]:
    """Tip/knob slope of the loading branches, (positive side, negative side).

    Fits a line to the samples moving away from zero with ``lo_deg <= |knob| <= hi_deg`` (the
    tendon is being pulled there once ``lo_deg`` is past the dead zone).
    """
    q = np.asarray(knob_deg, dtype=np.float64)
    y = np.asarray(tip_deg, dtype=np.float64)
    dq = np.gradient(q)
    out = []
    for side in (1.0, -1.0):
        sel = (side * q >= lo_deg) & (side * q <= hi_deg) & (side * dq > 0.0)
        if np.count_nonzero(sel) < 3:
            raise SweepAnalysisError(f"no loading samples between {lo_deg} and {hi_deg} deg")
        out.append(float(np.polyfit(q[sel], y[sel], 1)[0]))
    return out[0], out[1]


def releasing_slope(
    knob_deg: ArrayLike, tip_deg: ArrayLike, lo_deg: float, hi_deg: float
) -> tuple[float, float]:
    """Tip/knob slope of the releasing branches (moving towards zero), like :func:`loaded_slope`."""
    q = np.asarray(knob_deg, dtype=np.float64)
    y = np.asarray(tip_deg, dtype=np.float64)
    return loaded_slope(q[::-1], y[::-1], lo_deg, hi_deg)


def _binned(q: FloatArray, y: FloatArray, width_deg: float) -> tuple[FloatArray, FloatArray]:
    """Median tip per knob bin of a monotone pass (the fit's cost independent of the rate)."""
    edges = np.arange(q[0], q[-1] + width_deg, width_deg)
    idx = np.clip(np.searchsorted(edges, q, side="right") - 1, 0, edges.size - 1)
    keep = np.unique(idx)
    qb = np.array([np.median(q[idx == k]) for k in keep])
    yb = np.array([np.median(y[idx == k]) for k in keep])
    return qb, yb


def _hinge_fit(q: FloatArray, y: FloatArray, knots: FloatArray) -> tuple[float, FloatArray]:
    """Least squares of a continuous piecewise line: flat before the first knot (the held
    tip of the paper's backlash), a free slope after each knot. (sum of squares, coefficients)"""
    basis = np.column_stack([np.ones_like(q)] + [np.maximum(q - k, 0.0) for k in knots])
    coef, *_ = np.linalg.lstsq(basis, y, rcond=None)
    r = y - basis @ coef
    return float(r @ r), coef


def _rising_pass_lines(q: FloatArray, tip: FloatArray, thr: float) -> tuple[float, float]:
    """(backlash, dead zone edge) of a rising pass as the corners of the paper's lines."""
    b_thr, d_thr = _rising_pass_measures(q, tip, thr)
    if not (np.isfinite(b_thr) and np.isfinite(d_thr)):
        return float("nan"), float("nan")
    qb, yb = _binned(q, tip, 0.5)
    q0, q1 = float(qb[0]), float(qb[-1])
    lo, hi = q0 + 0.25, q1 - 0.25

    def cost(k: FloatArray) -> float:
        if not lo < k[0] < k[1] < k[2] < hi:
            return np.inf
        return _hinge_fit(qb, yb, k)[0]

    b0, d0 = q[0] + b_thr, d_thr
    if not lo < b0 < d0 < hi:
        return float("nan"), float("nan")
    # the plateau's start is not read by the threshold: try a few and polish the best
    starts = [np.array([b0, b0 + f * (d0 - b0), d0]) for f in (0.2, 0.4, 0.6, 0.8)]
    best = min(starts, key=cost)
    fit = minimize(cost, best, method="Nelder-Mead",
                   options={"xatol": 0.05, "fatol": 1e-9, "maxiter": 600})
    k = fit.x if np.isfinite(fit.fun) else best
    _, coef = _hinge_fit(qb, yb, k)
    release, plateau, loaded = coef[1], coef[1] + coef[2], coef[1] + coef[2] + coef[3]
    # the lines must be the paper's: a release, a plateau flatter than both, a loaded branch
    if not (release > 0.0 and loaded > 0.0 and abs(plateau) < 0.5 * min(release, loaded)):
        return float("nan"), float("nan")
    return float(k[0] - q[0]), float(k[2])


def measure_by_lines(knob_deg: ArrayLike, tip_deg: ArrayLike,
                     threshold_deg: float = 1.0) -> DeadZoneBacklash:
    """``D_pos, D_neg, B_pos, B_neg`` (knob degrees) as the corners of the paper's lines.

    Each pass is fitted with one continuous piecewise line: the tip held after the reversal
    (flat), the release line, the dead-zone plateau (its own slope, so a tip that creeps along
    the plateau does not move the edge) and the loaded line. B is the knob travel from the
    reversal to the held line's corner with the release line, D the plateau's corner with the
    loaded line. The threshold reading (:func:`measure_dead_zone_backlash`) only seeds the fit.
    A pass whose fitted lines are not these (no plateau flatter than both branches) counts as
    NaN; each value is the median over passes.
    """
    q = np.asarray(knob_deg, dtype=np.float64)
    y = np.asarray(tip_deg, dtype=np.float64)
    measure_dead_zone_backlash(q, y, threshold_deg)  # the same input checks, one message each
    return _over_passes(q, y, threshold_deg, _rising_pass_lines)
