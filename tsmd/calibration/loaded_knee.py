"""Where a unit's loaded branch bends: the knee of its loaded current ramp.

A spine that transforms under load (nitinol's superelastic plateau) gives the loaded branch a
knee: past the dead-zone edge the motor current first rises steeply (elastic start), then far
less (the moment holds on its plateau), and the tip's knee moves with the current's from unit
to unit (docs/model.md, session 15). The knee is read per side by a continuous two-line fit of
the filtered current against travel past the edge on the passes that load that side, one knee
per pass; the sweep's knee is their median, its uncertainty from their scatter. A ramp whose
slope does not fall by :data:`KNEE_SLOPE_DROP` has no knee (None).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tsmd.calibration.signal import FloatArray

KNEE_FIT_TRAVEL_DEG: tuple[float, float] = (3.0, 60.0)
"""Travel past the edge the two-line fit uses (the fast sweep's +-90 deg reaches about 60 past
a 25 deg edge; the first degrees are the engagement's rounding)."""
KNEE_SEARCH_DEG: tuple[float, float] = (10.0, 50.0)
"""Where the knee may lie."""
KNEE_SEARCH_STEP_DEG = 0.1
KNEE_SLOPE_DROP = 0.5
"""The slope after the knee must be below this share of the slope before (else no knee)."""
MIN_PASS_SAMPLES = 40


@dataclass(frozen=True)
class LoadedKnee:
    """One side's knee: travel past the dead-zone edge (deg) and its 95 % uncertainty."""

    travel_deg: float
    u95_deg: float
    passes: int


def hinge_knee_deg(travel_deg: FloatArray, current_A: FloatArray) -> tuple[float, float] | None:
    """Least-squares knee of ``I = a + b u + c max(u - K, 0)`` (K on a grid) and the slope
    ratio (b + c) / b at it; None without enough samples or a rising ramp."""
    u = np.asarray(travel_deg, float)
    y = np.asarray(current_A, float)
    lo, hi = KNEE_FIT_TRAVEL_DEG
    sel = (u >= lo) & (u <= hi) & np.isfinite(y)
    u, y = u[sel], y[sel]
    if u.size < MIN_PASS_SAMPLES or u.max() < KNEE_SEARCH_DEG[1]:
        return None
    best: tuple[float, float, float] | None = None
    for k in np.arange(KNEE_SEARCH_DEG[0], KNEE_SEARCH_DEG[1] + 1e-9, KNEE_SEARCH_STEP_DEG):
        a = np.column_stack([np.ones_like(u), u, np.maximum(u - k, 0.0)])
        coef, *_ = np.linalg.lstsq(a, y, rcond=None)
        sse = float(np.sum((a @ coef - y) ** 2))
        if coef[1] > 0 and (best is None or sse < best[0]):
            best = (sse, float(k), float((coef[1] + coef[2]) / coef[1]))
    return None if best is None else (best[1], best[2])


def read_loaded_knee(pos_deg: FloatArray, current_A: FloatArray, dead_zone_deg: float,
                     side: int) -> LoadedKnee | None:
    """The knee of one side (``side`` +1 / -1) of a sweep: per pass moving out past the edge
    ``dead_zone_deg``, the hinge fit of the side's current (sign-mirrored) against travel past
    the edge; None where no pass shows a knee."""
    pos = np.asarray(pos_deg, float)
    cur = np.asarray(current_A, float)
    if not math.isfinite(dead_zone_deg) or pos.size < 3:
        return None
    outward = side * np.gradient(pos) > 0
    # passes: runs of samples moving outward
    edges = np.flatnonzero(np.diff(outward.astype(int)))
    starts = np.concatenate([[0], edges + 1])
    stops = np.concatenate([edges + 1, [pos.size]])
    knees = []
    for a, b in zip(starts, stops, strict=True):
        if not outward[a]:
            continue
        fit = hinge_knee_deg(side * (pos[a:b] - dead_zone_deg), side * cur[a:b])
        if fit is not None and fit[1] < KNEE_SLOPE_DROP:
            knees.append(fit[0])
    if not knees:
        return None
    k = np.asarray(knees)
    # no finer than the search grid (two passes that agree do not make it exact)
    u95 = (max(2.0 * float(np.std(k, ddof=1)) / math.sqrt(k.size), KNEE_SEARCH_STEP_DEG)
           if k.size > 1 else math.inf)
    return LoadedKnee(round(float(np.median(k)), 2), round(u95, 2), int(k.size))


def sweep_knees(pos_deg: FloatArray, current_A: FloatArray, dead_zone_pos_deg: float,
                dead_zone_neg_deg: float
                ) -> tuple[tuple[float, float] | None, tuple[float, float] | None]:
    """Both sides' knees (positive, negative) of one sweep and their u95s: None where a side
    shows none; the u95s None where a side had a single pass."""
    knees = [read_loaded_knee(pos_deg, current_A, d, side)
             for d, side in ((dead_zone_pos_deg, 1), (dead_zone_neg_deg, -1))]
    if knees[0] is None or knees[1] is None:
        return None, None
    u95 = (knees[0].u95_deg, knees[1].u95_deg)
    return ((knees[0].travel_deg, knees[1].travel_deg),
            u95 if all(math.isfinite(v) and v <= 90.0 for v in u95) else None)
