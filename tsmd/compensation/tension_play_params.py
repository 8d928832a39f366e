"""One knob's tension-play parameters and their profile/sheet block, validated.

The model these parameters drive is :mod:`tsmd.compensation.tension_play`; this module holds
what a profile stores of it (per other-knob angle: dead-zone edges, ``beta``, ``x0``; the
sheet's omega, plateau heights and product templates), so the profile schema reads and writes
parameters without importing the model.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.compensation.level_grid import (
    LevelGrid,
    level_grid_from_mapping,
    level_grid_to_mapping,
)
from tsmd.compensation.loaded_shape import (
    LoadedShape,
    ShapeGrid,
    shape_from_mapping,
    shape_grid_from_mapping,
    shape_grid_to_mapping,
    shape_to_mapping,
)
from tsmd.compensation.release_round import RELEASE_ROUND_RANGE, RELEASE_SHIFT_RANGE
from tsmd.compensation.reversal_release import (
    ReleaseEndShape,
    release_end_shape_from_mapping,
    release_end_shape_to_mapping,
)

BETA_RANGE: tuple[float, float] = (0.0, 0.8)
"""Backlash per knob degree of load: 0 = no backlash; 0.8 = release slope 5 omega."""
OMEGA_RANGE: tuple[float, float] = (0.2, 5.0)
"""Plausible loaded tip/knob slopes (tip deg per knob deg)."""
OTHER_TIP_GAIN_RANGE: tuple[float, float] = (-0.5, 0.5)
"""Plausible tip degrees of one plane per tip degree of the other (a twisted shaft: ~0.09)."""


@dataclass(frozen=True)
class TensionPlayParams:
    """One knob's tension-play parameters; tuples are sampled on ``other_knob_deg``.

    ``dead_zone_*_deg``: where the tip leaves its plateau (the current's edge).
    ``backlash_gain_*``: beta, knob degrees of backlash per knob degree of load at the reversal.
    ``zero_load_*_deg``: where the loaded current ramp extrapolates to zero (the tension's zero).
    ``height_*_deg``: plateau heights from the data sheet's reference points (paper, H).
    ``lag_s``: delay of the drive's actual position behind its command.
    ``fresh_hold_deg``: how much further a fresh (never loaded) catheter's knob travels on its
    first release before the other tendon takes over
    (:func:`tsmd.compensation.fresh_play.fresh_branches`); 0: not known.
    ``fresh_edge_delay_deg``: how much later (knob deg) its first loading's current edge lies
    than the conditioned one's; from there the tip leaves straight (0) along the loaded slope.
    ``other_tip_gain``: the product's tip degrees in this plane per tip degree of the other
    (data sheet, tracked on its unit; 0: the planes do not turn into each other).
    ``shape_grid``: the product's templates (positive, negative side) over the other knob's
    angle (data sheet); where given they replace ``shape_pos``/``shape_neg`` in the model.
    ``loaded_knee_deg``: the unit's knee of the loaded current ramp (positive, negative side;
    travel past the edge, other knob at 0: :mod:`tsmd.calibration.loaded_knee`), with
    ``loaded_knee_u95_deg``; ``sheet_loaded_knee_deg`` the data-sheet unit's, read the same way.
    Where both knees are given method ours moves the templates' knee to the unit's
    (:mod:`tsmd.compensation.knee_map`); otherwise the templates as they are.
    ``release_round`` / ``release_shift``: the product's rounded release (data sheet,
    :mod:`tsmd.compensation.release_round`), in backlashes at a 90 deg reversal; 0: sharp.
    ``level_grid``: the product's shift of each side's plateau height over the other knob's
    angle (data sheet, :mod:`tsmd.compensation.level_grid`); None: H at every angle.
    ``release_end``: the product's release end per reversal (data sheet ``release_end_shape``,
    :mod:`tsmd.compensation.reversal_release`); None: the static release lines.
    ``hold_at_home``: the product's choice (data sheet, :mod:`tsmd.datasheet_home_hold`) that
    this knob keeps its command at rest inside its plateau band while the other knob moves its
    branches; False: it follows them.
    """

    omega: float
    height_pos_deg: float
    height_neg_deg: float
    other_knob_deg: tuple[float, ...]
    dead_zone_pos_deg: tuple[float, ...]
    dead_zone_neg_deg: tuple[float, ...]
    backlash_gain_pos: tuple[float, ...]
    backlash_gain_neg: tuple[float, ...]
    zero_load_pos_deg: tuple[float, ...]
    zero_load_neg_deg: tuple[float, ...]
    lag_s: float = 0.0
    fresh_hold_deg: float = 0.0
    fresh_edge_delay_deg: float = 0.0
    shape_pos: LoadedShape | None = None
    shape_neg: LoadedShape | None = None
    other_tip_gain: float = 0.0
    shape_grid: tuple[ShapeGrid, ShapeGrid] | None = None
    loaded_knee_deg: tuple[float, float] | None = None
    loaded_knee_u95_deg: tuple[float, float] | None = None
    sheet_loaded_knee_deg: tuple[float, float] | None = None
    release_round: float = 0.0
    release_shift: float = 0.0
    level_grid: LevelGrid | None = None
    release_end: ReleaseEndShape | None = None
    hold_at_home: bool = False

    def columns(self) -> NDArray[np.float64]:
        """(n, 6): D_pos, D_neg, beta_pos, beta_neg, x0_pos, x0_neg per grid point."""
        return np.column_stack([self.dead_zone_pos_deg, self.dead_zone_neg_deg,
                                self.backlash_gain_pos, self.backlash_gain_neg,
                                self.zero_load_pos_deg, self.zero_load_neg_deg]).astype(float)


_ROWS: dict[str, tuple[float, float]] = {
    "dead_zone_pos_deg": (0.0, 90.0), "dead_zone_neg_deg": (-90.0, 0.0),
    "backlash_gain_pos": BETA_RANGE, "backlash_gain_neg": BETA_RANGE,
    "zero_load_pos_deg": (-90.0, 90.0), "zero_load_neg_deg": (-90.0, 90.0),
}
_SCALARS: dict[str, tuple[float, float]] = {
    "omega": OMEGA_RANGE, "height_pos_deg": (-90.0, 90.0), "height_neg_deg": (-90.0, 90.0),
    "lag_s": (0.0, 1.0), "fresh_hold_deg": (0.0, 90.0), "fresh_edge_delay_deg": (-45.0, 45.0),
    "other_tip_gain": OTHER_TIP_GAIN_RANGE, "release_round": RELEASE_ROUND_RANGE,
    "release_shift": RELEASE_SHIFT_RANGE,
}
_OPTIONAL = {"lag_s", "fresh_hold_deg", "fresh_edge_delay_deg", "other_tip_gain",
             "release_round", "release_shift"}
_WRITTEN_IF_SET = {"fresh_hold_deg", "fresh_edge_delay_deg", "other_tip_gain", "release_round",
                   "release_shift"}
_SHAPES = {"loaded_shape_pos": "shape_pos", "loaded_shape_neg": "shape_neg"}
_SHAPE_GRID = "loaded_shape_grid"
_LEVEL_GRID = "loaded_level_grid"
_RELEASE_END = "release_end_shape"
_HOLD = "hold_at_home"
"""A flag, written only when set."""
_KNEES = ("loaded_knee_deg", "loaded_knee_u95_deg", "sheet_loaded_knee_deg")
"""Optional pairs (positive, negative side), written only when set."""


def _number(value: Any, name: str, lo: float, hi: float) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{name}: must be a number, got {value!r}")
    f = float(value)
    if not math.isfinite(f):
        raise ValueError(f"{name}: is not finite")
    if not lo <= f <= hi:
        raise ValueError(f"{name}: {f} is outside [{lo}, {hi}]")
    return f


def _numbers(values: Any, name: str, n: int | None, lo: float, hi: float) -> tuple[float, ...]:
    if isinstance(values, str) or not isinstance(values, Sequence):
        raise ValueError(f"{name}: must be a list of numbers")
    if n is not None and len(values) != n:
        raise ValueError(f"{name}: must have {n} values, got {len(values)}")
    return tuple(_number(v, f"{name}[{i}]", lo, hi) for i, v in enumerate(values))


def tension_play_from_mapping(m: Mapping[str, Any]) -> TensionPlayParams:
    """Validate a profile's ``tension_play`` block (ValueError naming the key)."""
    known = {"other_knob_deg", *_ROWS, *_SCALARS, *_SHAPES, _SHAPE_GRID, _LEVEL_GRID, *_KNEES,
             _RELEASE_END, _HOLD}
    for key in m:
        if key not in known:
            raise ValueError(f"{key}: unknown key")
    for key in (known - _OPTIONAL - set(_SHAPES) - {_SHAPE_GRID, _LEVEL_GRID, _RELEASE_END, _HOLD}
                - set(_KNEES)):
        if key not in m:
            raise ValueError(f"{key}: missing key")
    grid = _numbers(m["other_knob_deg"], "other_knob_deg", None, -180.0, 180.0)
    if len(grid) < 2 or any(b <= a for a, b in itertools.pairwise(grid)):
        raise ValueError("other_knob_deg: needs >= 2 strictly increasing values")
    s = {k: _number(m.get(k, 0.0), k, *r) for k, r in _SCALARS.items()}
    r = {k: _numbers(m[k], k, len(grid), *lim) for k, lim in _ROWS.items()}
    pos_shape, neg_shape = (shape_from_mapping(m[k], k) if m.get(k) is not None else None
                            for k in _SHAPES)
    knees = {k: _knee_pair(m[k], k) if m.get(k) is not None else None for k in _KNEES}
    hold = m.get(_HOLD, False)
    if not isinstance(hold, bool):
        raise ValueError(f"{_HOLD}: must be true or false, got {hold!r}")
    return TensionPlayParams(
        s["omega"], s["height_pos_deg"], s["height_neg_deg"], grid, r["dead_zone_pos_deg"],
        r["dead_zone_neg_deg"], r["backlash_gain_pos"], r["backlash_gain_neg"],
        r["zero_load_pos_deg"], r["zero_load_neg_deg"], s["lag_s"], s["fresh_hold_deg"],
        s["fresh_edge_delay_deg"], pos_shape, neg_shape, other_tip_gain=s["other_tip_gain"],
        shape_grid=(shape_grid_from_mapping(m[_SHAPE_GRID], _SHAPE_GRID)
                    if m.get(_SHAPE_GRID) is not None else None),
        release_round=s["release_round"], release_shift=s["release_shift"],
        level_grid=(level_grid_from_mapping(m[_LEVEL_GRID], _LEVEL_GRID)
                    if m.get(_LEVEL_GRID) is not None else None),
        release_end=(release_end_shape_from_mapping(m[_RELEASE_END], _RELEASE_END)
                     if m.get(_RELEASE_END) is not None else None), hold_at_home=hold, **knees)


def _knee_pair(values: Any, name: str) -> tuple[float, float]:
    pos, neg = _numbers(values, name, 2, 0.0, 90.0)
    return pos, neg


def tension_play_to_mapping(p: TensionPlayParams) -> dict[str, Any]:
    out: dict[str, Any] = {k: float(getattr(p, k)) for k in _SCALARS
                           if k not in _WRITTEN_IF_SET or getattr(p, k) != 0.0}
    out["other_knob_deg"] = list(p.other_knob_deg)
    out.update({k: list(getattr(p, k)) for k in _ROWS})
    for key, attr in _SHAPES.items():
        shape = getattr(p, attr)
        if shape is not None:
            out[key] = shape_to_mapping(shape)
    if p.shape_grid is not None:
        out[_SHAPE_GRID] = shape_grid_to_mapping(*p.shape_grid)
    if p.level_grid is not None:
        out[_LEVEL_GRID] = level_grid_to_mapping(p.level_grid)
    if p.release_end is not None:
        out[_RELEASE_END] = release_end_shape_to_mapping(p.release_end)
    for key in _KNEES:
        pair = getattr(p, key)
        if pair is not None:
            out[key] = [float(v) for v in pair]
    if p.hold_at_home:
        out[_HOLD] = True
    return out
