"""A product template's knee moved to where each unit's current puts it.

The loaded-branch templates (:mod:`tsmd.compensation.loaded_shape`) are measured on the data
sheet's unit, but where a transforming spine's knee sits varies by unit, and the current shows
it (:mod:`tsmd.calibration.loaded_knee`; docs/model.md, session 15). With the sheet unit's knee
``K_s`` and the unit's ``K_u`` (both read from current the same way), the template's slopes are
laid on the unit's travel: the stretch before the knee scaled by ``K_u / K_s``, the part after
it shifted by ``K_u - K_s``. Each piece keeps its slope, so a straight template (and a grid
angle whose template has no knee) stays exactly as it was.
"""

from __future__ import annotations

from tsmd.compensation.loaded_shape import MAX_SHAPE_KNOTS, LoadedShape, ShapeGrid

KNEE_RATIO_RANGE: tuple[float, float] = (0.8, 1.25)
"""Bounds of ``K_u / K_s``: a reading further off is held at the bound (the family's units
read 0.92-1.05 of unit 0's; a ramp misread must not fold the template)."""


def knee_ratio(sheet_knee_deg: float, unit_knee_deg: float) -> float:
    """``K_u / K_s`` held inside :data:`KNEE_RATIO_RANGE`."""
    lo, hi = KNEE_RATIO_RANGE
    return min(max(unit_knee_deg / sheet_knee_deg, lo), hi)


def moved_knee(shape: LoadedShape, sheet_knee_deg: float, unit_knee_deg: float) -> LoadedShape:
    """``shape`` with its travel axis mapped from the sheet unit's knee to the unit's: the
    sheet's travel ``t`` lands at ``t * r`` before ``K_s`` and at ``t - K_s + K_s r`` after
    (``r`` = :func:`knee_ratio`); the template's slope on each piece is kept."""
    ratio = knee_ratio(sheet_knee_deg, unit_knee_deg)
    if ratio == 1.0:
        return shape
    ks = sheet_knee_deg
    t, y = list(shape.travel_deg), list(shape.shaped_deg)
    if ks not in t:  # the knee becomes a knot (beyond the last one the last piece's slope)
        t.append(ks)
        t.sort()
        y = [shape.at(v) for v in t]
        if len(t) > MAX_SHAPE_KNOTS:  # drop the knot nearest the knee but the knee itself
            i = t.index(ks)
            j = i - 1 if i == len(t) - 1 or (i > 0 and ks - t[i - 1] < t[i + 1] - ks) else i + 1
            del t[j], y[j]
    u = [v * ratio if v <= ks else v - ks + ks * ratio for v in t]
    out = [0.0]
    for i in range(1, len(t)):
        slope = (y[i] - y[i - 1]) / (t[i] - t[i - 1])
        out.append(out[-1] + slope * (u[i] - u[i - 1]))
    return LoadedShape(tuple(round(v, 6) for v in u), tuple(round(v, 6) for v in out))


def moved_grid(grid: ShapeGrid, sheet_knee_deg: float, unit_knee_deg: float) -> ShapeGrid:
    """Every template of one side's grid with its knee moved (:func:`moved_knee`)."""
    return ShapeGrid(grid.other_knob_deg,
                     tuple(moved_knee(s, sheet_knee_deg, unit_knee_deg) for s in grid.shapes))
