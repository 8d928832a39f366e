"""How far the tip's loaded level follows the current's edge over the other knob's angle.

Each unit's loaded line ``y = H + omega (x - D(a))`` moves with the edge ``D`` the current reads
at the other knob's angle ``a``. Where the other plane's bend takes up this plane's ropes (a
snake-bone section of rolling joints: snakedent, session 23) the current's edge moves inward by
up to 5-8 deg at the other knob's +-90, but the tip does not engage earlier: the other plane's
rope tension presses the stack harder and its joint friction holds the tip back by about as
much. On snakedent's sheet unit the tip's miss per side and other-knob angle is
``share * omega * (D(a) - D(0))`` with share 0.85 (phi1) / 0.91 (phi2), the misses' RMS
3.3 / 3.8 deg -> 0.3 / 0.5 with the share (docs/model.md, session 23). The share is the
product's (data sheet, ``edge_level_share``, tracked once on its unit); the edges are each
unit's own, so every unit gets its own shift from its own current. The shift enters the model
as a level grid (:mod:`tsmd.compensation.level_grid`): it moves the side's loaded branch, its
flat and its release line together. Pure functions, no I/O.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tsmd.compensation.level_grid import (
    EDGE_LEVEL_SHARE_RANGE,
    LEVEL_SHIFT_RANGE_DEG,
    LevelGrid,
)


def _at_zero(other_deg: Sequence[float], values: Sequence[float]) -> float:
    return float(np.interp(0.0, np.asarray(other_deg, float), np.asarray(values, float)))


def edge_level_shifts(share: float, omega: float, other_deg: Sequence[float],
                      edges_deg: Sequence[float]) -> tuple[float, ...]:
    """One side's level shift (tip deg) at each grid angle, ``share * omega * (D(a) - D(0))``:
    an edge moved inward by a degree moves the loaded line outward by ``omega``, the shift takes
    ``share`` of that back; held inside
    :data:`~tsmd.compensation.level_grid.LEVEL_SHIFT_RANGE_DEG`."""
    lo, hi = LEVEL_SHIFT_RANGE_DEG
    zero = _at_zero(other_deg, edges_deg)
    return tuple(round(min(max(share * omega * (float(d) - zero), lo), hi), 3)
                 for d in edges_deg)


def edge_level_grid(share: float, omega: float, other_deg: Sequence[float],
                    dead_zone_pos_deg: Sequence[float], dead_zone_neg_deg: Sequence[float],
                    product_grid: LevelGrid | None = None) -> LevelGrid | None:
    """A unit's level grid from the product's share and its own edges over the grid, plus the
    product's own level grid (data sheet, measured under the share) where it has one; None with
    fewer than two grid angles and no product grid. ValueError for a share outside
    :data:`EDGE_LEVEL_SHARE_RANGE`."""
    lo, hi = EDGE_LEVEL_SHARE_RANGE
    if not lo <= share <= hi:
        raise ValueError(f"edge_level_share {share!r} outside [{lo}, {hi}]")
    if len(other_deg) < 2:
        return product_grid
    pos = edge_level_shifts(share, omega, other_deg, dead_zone_pos_deg)
    neg = edge_level_shifts(share, omega, other_deg, dead_zone_neg_deg)
    if product_grid is not None:
        added = [product_grid.at(float(a)) for a in other_deg]
        pos = tuple(round(p + s[0], 3) for p, s in zip(pos, added, strict=True))
        neg = tuple(round(n + s[1], 3) for n, s in zip(neg, added, strict=True))
    return LevelGrid(tuple(float(a) for a in other_deg), pos, neg)
