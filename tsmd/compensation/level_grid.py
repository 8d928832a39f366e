"""The product's loaded level over the other knob's angle (session 21).

The plateau heights H (the level each side's loaded branch leaves its flat at) come from the
data sheet's reference points, read with the other knob at 0. With the other plane bent the
tip stands further from its zero on both flats and runs short on both loaded branches by about
as much (nitinol's unit 0: 2-2.5 deg at the other knob's +-60, 3.5-4 at +-90, each side inward;
development unit 1 the same in sign and size): a level, not a shape, that the current does not
show (its edges and backlash read alike). It is the product's, measured on the data sheet's
unit from its tip (:mod:`tsmd.datasheet_level_grid`), as a shift of each side's H per
other-knob angle, 0 at the other knob's 0 where H was read. The shift moves the side's loaded
branch, its flat and its release line together (H moves them all in the model).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

LEVEL_SHIFT_RANGE_DEG: tuple[float, float] = (-30.0, 30.0)
"""A shift beyond this is not a level but a mis-read (bad input)."""
EDGE_LEVEL_SHARE_RANGE: tuple[float, float] = (0.0, 1.5)
"""Plausible shares of the current's edge movement the tip's level does not follow (data
sheet's ``edge_level_share``, :mod:`tsmd.calibration.edge_level`): 0 the tip follows the edge,
1 it keeps its level at the other knob's 0; beyond 1.5 no edge explains the miss."""


@dataclass(frozen=True)
class LevelGrid:
    """Each side's shift of its plateau height over the other knob's angle (tip deg: the
    positive side's H gets ``pos_deg``, the negative side's ``neg_deg``); linear between the
    angles, the end ones held."""

    other_knob_deg: tuple[float, ...]
    pos_deg: tuple[float, ...]
    neg_deg: tuple[float, ...]

    def __post_init__(self) -> None:
        n = len(self.other_knob_deg)
        if n < 2 or any(b <= a for a, b in itertools.pairwise(self.other_knob_deg)):
            raise ValueError("other_knob_deg: needs >= 2 strictly increasing values")
        if len(self.pos_deg) != n or len(self.neg_deg) != n:
            raise ValueError(f"pos_deg / neg_deg: need {n} values each (one per angle)")

    def at(self, other_deg: float) -> tuple[float, float]:
        """(positive side's, negative side's) shift at the other knob's angle."""
        at = np.asarray(self.other_knob_deg, dtype=float)
        return (float(np.interp(other_deg, at, np.asarray(self.pos_deg, dtype=float))),
                float(np.interp(other_deg, at, np.asarray(self.neg_deg, dtype=float))))


def _numbers(values: Any, name: str, lo: float, hi: float) -> tuple[float, ...]:
    if isinstance(values, str) or not isinstance(values, Sequence):
        raise ValueError(f"{name}: must be a list of numbers")
    out = []
    for i, v in enumerate(values):
        if isinstance(v, bool) or not isinstance(v, int | float) or not lo <= float(v) <= hi:
            raise ValueError(f"{name}[{i}]: must be a number in [{lo}, {hi}], got {v!r}")
        out.append(float(v))
    return tuple(out)


def level_grid_from_mapping(m: Any, where: str) -> LevelGrid:
    """Validate a ``loaded_level_grid`` block (ValueError naming the key that is wrong)."""
    if not isinstance(m, Mapping):
        raise ValueError(f"{where}: must be a mapping with other_knob_deg, pos_deg, neg_deg")
    unknown = sorted(set(m) - {"other_knob_deg", "pos_deg", "neg_deg"})
    if unknown:
        raise ValueError(f"{where}.{unknown[0]}: unknown key")
    for key in ("other_knob_deg", "pos_deg", "neg_deg"):
        if key not in m:
            raise ValueError(f"{where}.{key}: missing key")
    try:
        return LevelGrid(_numbers(m["other_knob_deg"], f"{where}.other_knob_deg", -180.0, 180.0),
                         _numbers(m["pos_deg"], f"{where}.pos_deg", *LEVEL_SHIFT_RANGE_DEG),
                         _numbers(m["neg_deg"], f"{where}.neg_deg", *LEVEL_SHIFT_RANGE_DEG))
    except ValueError as exc:
        msg = str(exc)
        raise ValueError(msg if msg.startswith(where) else f"{where}: {msg}") from None


def level_grid_to_mapping(g: LevelGrid) -> dict[str, list[float]]:
    return {"other_knob_deg": [float(v) for v in g.other_knob_deg],
            "pos_deg": [round(float(v), 3) for v in g.pos_deg],
            "neg_deg": [round(float(v), 3) for v in g.neg_deg]}
