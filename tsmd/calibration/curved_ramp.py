"""A loaded ramp that bends smoothly is not a knee: the curved-hinge check on the edge fit.

:func:`tsmd.calibration.branch_fit.fit_edge` takes a knee (a steep first rise turning into the
loaded ramp at a corner, where the tip starts to move) when two lines explain the current better
than one by the change-point penalty, and reads the edge at the corner. A loaded current that
flattens gradually (jawcrimp: the rope tensions against the oesophagus wall's stiff start, about
7 mN m per knob degree, then ~4 as the wall saturates; the tip moves from the first degree)
also fits two lines better than one, by about the penalty: half-cycle by half-cycle the fit
then took the knee's corner (10-12 deg past the edge) or the hinge, and the sweep's edges fell
in two groups 10-12 deg apart. A corner is a corner only if it explains the current better than a
smooth bend: here the ramp past the edge as a parabola (level, slope, curvature; one fewer free
parameter than the knee). The knee stands only when it beats that curved hinge by the penalty
too; otherwise the edge is where the level meets the curve (or the straight hinge's, when the
curve gains nothing over it).
"""

from __future__ import annotations

import numpy as np

from tsmd.calibration.signal import FloatArray

CURVE_CHUNK = 128
"""Candidate edges fitted at once (a (edges, samples, 3) design matrix)."""


def curved_hinge(x: FloatArray, y: FloatArray, edges: FloatArray
                 ) -> tuple[FloatArray, FloatArray]:
    """For each candidate edge ``e``: residual sum of squares of
    ``y = L + s u + c u^2`` with ``u = (x - e)+`` (least squares) and the fitted slope at the
    edge ``s``; a fit whose ramp does not rise at the edge or that bends upwards (c > 0: a toe,
    which the hinge and knee already cover) gets an infinite residual."""
    rss = np.full(edges.size, np.inf)
    slope = np.zeros(edges.size)
    for a in range(0, edges.size, CURVE_CHUNK):
        e = edges[a:a + CURVE_CHUNK]
        u = np.maximum(x[None, :] - e[:, None], 0.0)
        basis = np.stack([np.ones_like(u), u, u * u], axis=2)
        gram = np.einsum("mni,mnj->mij", basis, basis) + 1e-12 * np.eye(3)
        rhs = np.einsum("mni,n->mi", basis, y)
        coef = np.linalg.solve(gram, rhs[..., None])[..., 0]
        fit = np.einsum("mni,mi->mn", basis, coef)
        ok = (coef[:, 1] > 0.0) & (coef[:, 2] <= 0.0)
        rss[a:a + CURVE_CHUNK] = np.where(ok, ((y[None, :] - fit) ** 2).sum(1), np.inf)
        slope[a:a + CURVE_CHUNK] = coef[:, 1]
    return rss, slope


def best_curved_edge(x: FloatArray, y: FloatArray, edges: FloatArray
                     ) -> tuple[float, float] | None:
    """(edge, residual sum of squares) of the best curved hinge; None when none rises."""
    rss, _ = curved_hinge(x, y, edges)
    if not np.isfinite(rss).any():
        return None
    i = int(np.argmin(rss))
    return float(edges[i]), float(rss[i])
