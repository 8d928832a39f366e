"""The loaded branch's shape: a per-product template that bends the tension play's straight lines.

A straight loaded line ``y = H + omega (x - D)`` is what the paper and ours assume. A catheter
whose tip stiffens (slope falling along the branch) or engages softly (slope rising just past
the edge) departs from it by several degrees mid-range, and the motor current cannot say how
(docs/model.md, session 9: the current's curvature does not follow the tip's). A manufacturer
can measure the shape once per product with a tracker (``tsmd datasheet``): the tip's travel
beyond its plateau, in knob degrees at the sheet's omega, against the knob's travel beyond the
dead-zone edge. Each unit keeps its own edges, backlash and omega from its calibration; the
template only replaces the straight ``u`` by ``T(u)``: ``y = H + omega T(x - D)`` on the
positive side, ``y = H - omega T(D - x)`` on the negative one; the release line stays straight
and passes where the bent loaded line ends. Below the edge ``T(u) = u``.
The branches built with it: :func:`tsmd.compensation.shaped_play.shaped_branches`.
"""

from __future__ import annotations

import itertools
import math
from bisect import bisect_right
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

SHAPE_SLOPE_RANGE: tuple[float, float] = (0.05, 20.0)
"""Plausible local slopes of a template (``T'``, 1 = the sheet's omega): outside, the sheet is
not a loaded branch."""
MAX_SHAPE_KNOTS = 32


@dataclass(frozen=True)
class LoadedShape:
    """One side's template: ``shaped_deg = T(travel_deg)`` on knots from (0, 0), both strictly
    increasing; beyond the last knot the last piece's slope, below 0 the identity."""

    travel_deg: tuple[float, ...]
    shaped_deg: tuple[float, ...]

    def __post_init__(self) -> None:
        u, t = self.travel_deg, self.shaped_deg
        if len(u) != len(t) or not 2 <= len(u) <= MAX_SHAPE_KNOTS:
            raise ValueError(f"needs 2..{MAX_SHAPE_KNOTS} knots of travel and shaped angle, "
                             f"got {len(u)} and {len(t)}")
        if not all(math.isfinite(v) for v in (*u, *t)):
            raise ValueError("knots must be finite")
        if u[0] != 0.0 or t[0] != 0.0:
            raise ValueError(f"the first knot must be (0, 0), got ({u[0]}, {t[0]})")
        lo, hi = SHAPE_SLOPE_RANGE
        for (u0, t0), (u1, t1) in itertools.pairwise(zip(u, t, strict=True)):
            if not u1 > u0:
                raise ValueError(f"travel_deg must increase strictly ({u0} then {u1})")
            if not lo <= (t1 - t0) / (u1 - u0) <= hi:
                raise ValueError(f"slope {(t1 - t0) / (u1 - u0):.3f} between travel {u0} and "
                                 f"{u1} deg is outside [{lo}, {hi}]")

    @property
    def is_straight(self) -> bool:
        """T(u) = u everywhere: the straight line, which the model then uses as before."""
        return all(a == b for a, b in zip(self.travel_deg, self.shaped_deg, strict=True))

    @property
    def far_offset_deg(self) -> float:
        """T(u) - u at the last knot (the sheet's reference end): where the straight release
        line through the loaded line's far end sits (0 when straight)."""
        return self.shaped_deg[-1] - self.travel_deg[-1]

    def at(self, u_deg: float) -> float:
        """T(u)."""
        if u_deg <= 0.0:
            return u_deg
        return _interp(u_deg, self.travel_deg, self.shaped_deg)

    def inverse(self, t_deg: float) -> float:
        """u with T(u) = t."""
        if t_deg <= 0.0:
            return t_deg
        return _interp(t_deg, self.shaped_deg, self.travel_deg)


def _check_keys(m: Any, name: str, keys: tuple[str, ...]) -> None:
    """``m`` a mapping holding no key but ``keys``; ValueError naming the first defect."""
    if not isinstance(m, Mapping):
        raise ValueError(f"{name}: must be a mapping with {', '.join(keys[:-1])} and {keys[-1]}")
    unknown = set(m) - set(keys)
    if unknown:
        raise ValueError(f"{name}.{sorted(unknown)[0]}: unknown key")


def _numbers(v: Any, key: str) -> tuple[float, ...]:
    """``v`` as a tuple of floats; ValueError naming ``key`` if it is not a list of numbers."""
    if isinstance(v, str) or not isinstance(v, Sequence) or any(
            isinstance(x, bool) or not isinstance(x, int | float) for x in v):
        raise ValueError(f"{key}: must be a list of numbers")
    return tuple(float(x) for x in v)


def shape_from_mapping(m: Mapping[str, Any], name: str) -> LoadedShape:
    """A ``loaded_shape_*`` block (``travel_deg``, ``shaped_deg``); ValueError naming it."""
    _check_keys(m, name, ("travel_deg", "shaped_deg"))
    values = [_numbers(m.get(key), f"{name}.{key}") for key in ("travel_deg", "shaped_deg")]
    try:
        return LoadedShape(values[0], values[1])
    except ValueError as exc:
        raise ValueError(f"{name}: {exc}") from None


def shape_to_mapping(s: LoadedShape) -> dict[str, list[float]]:
    return {"travel_deg": list(s.travel_deg), "shaped_deg": list(s.shaped_deg)}


def curved(shape: LoadedShape | None) -> LoadedShape | None:
    """None for a missing or straight template (the model's straight lines, bit for bit)."""
    return None if shape is None or shape.is_straight else shape


def steepest_slope(*shapes: LoadedShape | None) -> float:
    """The templates' steepest piece (T', 1 when straight): the tip's fastest response."""
    slopes = [1.0]
    for shape in shapes:
        if shape is not None:
            u, t = shape.travel_deg, shape.shaped_deg
            slopes += [(t[i + 1] - t[i]) / (u[i + 1] - u[i]) for i in range(len(u) - 1)]
    return max(slopes)


def shaped_height(knob_deg: float, tip_deg: float, dead_zone_deg: float, omega: float,
                  shape: LoadedShape) -> float:
    """The plateau height H that puts a reference point (``knob_deg``, ``tip_deg``) on the
    shaped loaded line through the edge ``dead_zone_deg`` (either side; the straight case is
    ``paper.height_from_reference``)."""
    if knob_deg >= dead_zone_deg:
        return tip_deg - omega * shape.at(knob_deg - dead_zone_deg)
    return tip_deg + omega * shape.at(dead_zone_deg - knob_deg)


@dataclass(frozen=True)
class ShapeGrid:
    """One side's templates over the other knob's angle (the product's, data sheet).

    Where both planes bend one shared spine (a superelastic tube: nitinol), the other plane's
    bend has already transformed part of it, and the knob's knee moves or vanishes (unit 0
    phi1: tip 0.53 then 1.05 knob deg of travel per deg past the edge with the other knob at
    0, about 0.9 throughout at +-60, 0.97 at +-90; docs/model.md, Session 15). Between the
    angles the templates are interpolated linearly at every knot of either; outside, held.
    """

    other_knob_deg: tuple[float, ...]
    shapes: tuple[LoadedShape, ...]

    def __post_init__(self) -> None:
        g = self.other_knob_deg
        if len(g) != len(self.shapes) or len(g) < 2:
            raise ValueError(f"needs >= 2 other-knob angles, one template each, got {len(g)} "
                             f"and {len(self.shapes)}")
        if not all(math.isfinite(v) for v in g) or any(b <= a for a, b in itertools.pairwise(g)):
            raise ValueError(f"other_knob_deg must be finite and increase strictly: {list(g)}")

    def at(self, other_deg: float) -> LoadedShape:
        """The template at the other knob's angle (a weighted mean of its two neighbours)."""
        g = self.other_knob_deg
        if not other_deg > g[0]:
            return self.shapes[0]
        if not other_deg < g[-1]:
            return self.shapes[-1]
        i = bisect_right(g, other_deg) - 1
        w = (other_deg - g[i]) / (g[i + 1] - g[i])
        a, b = self.shapes[i], self.shapes[i + 1]
        if w == 0.0 or a == b:
            return a
        knots = sorted({*a.travel_deg, *b.travel_deg})
        return LoadedShape(tuple(knots),
                           tuple((1.0 - w) * a.at(u) + w * b.at(u) for u in knots))


def shape_grid_from_mapping(m: Mapping[str, Any], name: str) -> tuple[ShapeGrid, ShapeGrid]:
    """A ``loaded_shape_grid`` block (``other_knob_deg``, ``pos`` and ``neg``: one template per
    angle) as the two sides' grids; ValueError naming the key."""
    _check_keys(m, name, ("other_knob_deg", "pos", "neg"))
    grid = _numbers(m.get("other_knob_deg"), f"{name}.other_knob_deg")
    sides = []
    for side in ("pos", "neg"):
        raw = m.get(side)
        if isinstance(raw, str) or not isinstance(raw, Sequence):
            raise ValueError(f"{name}.{side}: must be a list of templates")
        shapes = tuple(shape_from_mapping(s, f"{name}.{side}[{i}]") for i, s in enumerate(raw))
        try:
            sides.append(ShapeGrid(grid, shapes))
        except ValueError as exc:
            raise ValueError(f"{name}.{side}: {exc}") from None
    return sides[0], sides[1]


def shape_grid_to_mapping(pos: ShapeGrid, neg: ShapeGrid) -> dict[str, Any]:
    if pos.other_knob_deg != neg.other_knob_deg:
        raise ValueError("the two sides' templates must share their other-knob angles")
    return {"other_knob_deg": list(pos.other_knob_deg),
            "pos": [shape_to_mapping(s) for s in pos.shapes],
            "neg": [shape_to_mapping(s) for s in neg.shapes]}


def _interp(x: float, xs: tuple[float, ...], ys: tuple[float, ...]) -> float:
    """Linear on strictly increasing ``xs``, the last piece extrapolated (x > xs[0] here)."""
    i = min(bisect_right(xs, x) - 1, len(xs) - 2)
    return ys[i] + (ys[i + 1] - ys[i]) * (x - xs[i]) / (xs[i + 1] - xs[i])
