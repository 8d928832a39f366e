"""Least-squares fits of a branch model to the current around a dead-zone edge.

The paper reads the edge where the constant-current phase ends. On a catheter whose tendon has a
slack *toe* (the tension rises gradually as the tendon engages) or friction lumps, that point
scatters and lands off the tip's edge. Here the edge is a line intersection, fitted by least
squares over a window of the half-cycle, like the tip's own edge is a line intersection:

* hinge: ``y = L + s (x - e)+``: the dead-zone level ``L`` and the loaded ramp meeting at ``e``;
* knee: ``y = L + s1 (x - e1)+ + (s2 - s1) (x - e2)+`` with ``s1 > ratio s2 > 0``: a steep first
  rise (the tendon stretching while the tip is still held) that turns into the loaded ramp at
  ``e2``, where the tip starts to move.

The knee is taken when it explains the current better than the hinge by more than the
change-point penalty (the same ``k sigma^2 log n`` as PELT); otherwise the hinge. Only the current
and the knob angle are used.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from tsmd.calibration.curved_ramp import best_curved_edge
from tsmd.calibration.signal import FloatArray


@dataclass(frozen=True)
class BranchFit:
    """The fitted edge (knob deg, direction-signed) and what was fitted."""

    edge_deg: float
    kind: str
    """"hinge", "knee" or "curved" (a ramp bending smoothly: its start, no corner)."""
    level_A: float
    ramp_A_per_deg: float
    residual_A: float
    """Root-mean-square residual of the chosen model."""


def _hinge(x: FloatArray, y: FloatArray, edges: FloatArray) -> tuple[FloatArray, FloatArray,
                                                                      FloatArray]:
    """For each candidate edge: residual sum of squares, level, ramp slope (least squares)."""
    h = np.maximum(x[None, :] - edges[:, None], 0.0)
    n = x.size
    sh, shh = h.sum(1), (h * h).sum(1)
    sy, shy = y.sum(), h @ y
    det = n * shh - sh * sh
    ok = det > 1e-12
    det = np.where(ok, det, 1.0)
    slope = (n * shy - sh * sy) / det
    level = (sy - slope * sh) / n
    rss = ((y[None, :] - level[:, None] - slope[:, None] * h) ** 2).sum(1)
    return np.where(ok, rss, np.inf), level, slope


KNEE_CHUNK = 128
"""Candidate pairs fitted at once: the design matrix is (pairs, samples, 3), so a whole
half-cycle's pairs at once held ~25 MiB; a chunk keeps it under 1.5 MiB with the same
arithmetic per pair."""


def _knee(x: FloatArray, y: FloatArray, e1: FloatArray,
          e2: FloatArray) -> tuple[FloatArray, FloatArray]:
    """For each candidate pair (e1, e2): residual sum of squares and coefficients
    (level, s1, s2 - s1)."""
    rss = np.empty(e1.size)
    coef = np.empty((e1.size, 3))
    for a in range(0, e1.size, KNEE_CHUNK):
        b = a + KNEE_CHUNK
        rss[a:b], coef[a:b] = _knee_chunk(x, y, e1[a:b], e2[a:b])
    return rss, coef


def _knee_chunk(x: FloatArray, y: FloatArray, e1: FloatArray,
                e2: FloatArray) -> tuple[FloatArray, FloatArray]:
    h1 = np.maximum(x[None, :] - e1[:, None], 0.0)
    h2 = np.maximum(x[None, :] - e2[:, None], 0.0)
    ones = np.ones_like(h1)
    basis = np.stack([ones, h1, h2], axis=2)  # (m, n, 3)
    gram = np.einsum("mni,mnj->mij", basis, basis) + 1e-12 * np.eye(3)
    rhs = np.einsum("mni,n->mi", basis, y)
    coef = np.linalg.solve(gram, rhs[..., None])[..., 0]
    fit = np.einsum("mni,mi->mn", basis, coef)
    return ((y[None, :] - fit) ** 2).sum(1), coef


def fit_edge(x: FloatArray, y: FloatArray, noise_A: float, *, knee_slope_ratio: float = 1.5,
             max_knee_deg: float = 15.0, penalty_k: float = 20.0,
             min_side_deg: float = 2.0, search_step_deg: float = 0.5,
             curve_check: bool = False) -> BranchFit | None:
    """The dead-zone edge in ``y`` (direction-signed current) over ``x`` (direction-signed knob
    angle, increasing), which holds the dead-zone level at its start and the loaded ramp at its
    end. None when no rising ramp fits."""
    if x.size < 8:
        return None
    lo, hi = x[0] + min_side_deg, x[-1] - min_side_deg
    if hi <= lo:
        return None
    edges = np.arange(lo, hi, search_step_deg)
    rss, level, slope = _hinge(x, y, edges)
    rss = np.where(slope > 0, rss, np.inf)
    if not np.isfinite(rss).any():
        return None
    i = int(np.argmin(rss))
    best = BranchFit(float(edges[i]), "hinge", float(level[i]), float(slope[i]),
                     math.sqrt(float(rss[i]) / x.size))
    e1, e2 = np.meshgrid(edges, edges, indexing="ij")
    pair = (e2 > e1) & (e2 - e1 <= max_knee_deg)
    if not pair.any():
        return best
    e1, e2 = e1[pair], e2[pair]
    krss, coef = _knee(x, y, e1, e2)
    s1, s2 = coef[:, 1], coef[:, 1] + coef[:, 2]
    valid = (s2 > 0) & (s1 > knee_slope_ratio * s2)
    if not valid.any():
        return best
    krss = np.where(valid, krss, np.inf)
    j = int(np.argmin(krss))
    penalty = penalty_k * max(noise_A, 1e-12) ** 2 * math.log(max(x.size, 2))
    if not krss[j] + penalty < rss[i]:
        return best
    # With curve_check, a corner only if it beats a smoothly bending ramp too
    # (tsmd.calibration.curved_ramp).
    curved = best_curved_edge(x, y, edges) if curve_check else None
    if curved is None or krss[j] + penalty < curved[1]:
        return BranchFit(float(e2[j]), "knee", float(coef[j, 0]), float(s2[j]),
                         math.sqrt(float(krss[j]) / x.size))
    if curved[1] + penalty < rss[i]:
        return replace(best, edge_deg=curved[0], kind="curved",
                       residual_A=math.sqrt(curved[1] / x.size))
    return best
