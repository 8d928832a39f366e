"""The data sheet's loaded-branch template, measured with the tracker on the sheet's unit.

The tip's travel beyond its dead-zone plateau, in knob degrees at the sheet's omega, against
the knob's travel beyond the dead-zone edge the calibration's current analysis finds on the
same sweep (:class:`tsmd.compensation.loaded_shape.LoadedShape`). Read per side on the whole
loaded passes of the sheet's sweep at fixed knob travels (:data:`SHAPE_KNOTS_DEG`), each a
local line fit over the passes' samples (the tracker's noise is ~0.2 deg), median over the
passes. A straight branch gives ``T(u) = u`` up to the tip's late departure from the plateau
near ``u = 0``; the blind plant's stiffening tip and the TEE probe's soft engagement give
their own shapes. The current cannot show the shape (docs/model.md, session 9), so it is a
product constant: each unit's calibration moves it with its own edge and omega.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from simrig.analysis import split_passes
from tsmd.compensation.loaded_shape import SHAPE_SLOPE_RANGE, LoadedShape

SHAPE_KNOTS_DEG = (0.0, 2.5, 5.0, 10.0, 15.0, 20.0, 30.0, 40.0, 50.0, 60.0)
"""Knob travel past the edge where the template is read (the last one is added at the end of
the branch): dense near the edge, where a soft engagement bends within 5-15 deg."""
END_MARGIN_DEG = 1.0
"""The last knot stands this far inside the pass's turning point."""
MIN_KNOT_GAP_DEG = 4.0
"""A fixed knot closer than this to the last one is dropped."""
FIT_HALF_DEG = 1.5
"""Half-width of the local line fit at each knot."""
PLATEAU_DEG = (-4.0, -1.0)
"""Where, before the edge, the tip's plateau is read."""
MIN_SAMPLES = 8


def _read_at(u: NDArray[np.float64], v: NDArray[np.float64], at_deg: float) -> float:
    """The tip (v) at knob travel ``at_deg`` from a line fitted to the samples around it."""
    sel = np.abs(u - at_deg) <= FIT_HALF_DEG
    if np.count_nonzero(sel) < MIN_SAMPLES:
        return float("nan")
    slope, icpt = np.polyfit(u[sel], v[sel], 1)
    return float(slope * at_deg + icpt)


def measure_loaded_shape(pos_deg: NDArray[np.float64], tip_deg: NDArray[np.float64],
                         edge_deg: float, omega: float, side: int) -> LoadedShape | None:
    """One side's template (``side`` +1: rising passes beyond ``edge_deg`` > 0; -1: falling
    passes beyond ``edge_deg`` < 0), or None where no whole loaded pass shows it."""
    if not (np.isfinite(edge_deg) and omega > 0):
        return None
    passes = []
    for a, b, direction in split_passes(np.asarray(pos_deg, dtype=float)):
        if direction != side:
            continue
        u = side * (pos_deg[a:b] - edge_deg)  # knob travel past the edge, outward
        v = side * tip_deg[a:b]
        plateau = (u >= PLATEAU_DEG[0]) & (u <= PLATEAU_DEG[1])
        if np.count_nonzero(plateau) >= MIN_SAMPLES and u.max() > MIN_KNOT_GAP_DEG:
            passes.append((u, (v - float(np.median(v[plateau]))) / omega))
    if not passes:
        return None
    top = min(float(u.max()) for u, _ in passes) - END_MARGIN_DEG
    knots = [k for k in SHAPE_KNOTS_DEG[1:] if k <= top - MIN_KNOT_GAP_DEG] + [top]
    values = np.nanmedian(np.array([[_read_at(u, t, k) for k in knots] for u, t in passes]),
                          axis=0)
    travel = [0.0]
    shaped = [0.0]
    lo, hi = SHAPE_SLOPE_RANGE
    for u_k, t_k in zip(knots, values, strict=True):
        if not np.isfinite(t_k):
            continue
        du = round(u_k, 2) - travel[-1]
        # monotone and within the plausible slopes, after the sheet's rounding to 0.01 deg
        t = min(max(round(float(t_k), 2), shaped[-1] + lo * du + 0.01), shaped[-1] + hi * du)
        travel.append(round(u_k, 2))
        shaped.append(round(t, 2))
    if len(travel) < 2:
        return None
    return LoadedShape(tuple(travel), tuple(shaped))
