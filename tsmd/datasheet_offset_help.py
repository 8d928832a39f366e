"""A backlash reading offset is written only where it helps on the sheet's unit (session 22).

The offset is the Hodges-Lehmann mean of the sheet unit's half-cycle errors (current minus tip,
:mod:`tsmd.datasheet_offset`). Where the half-cycles read one B a steady way off the tip, taking
the mean out moves each of them onto the tip. Where they read two different features of the
current (jawcrimp phi1 under the settle rule: most half-cycles within 0.5 deg of the tip, a
sweep's first one 5-10 deg late) the mean lies between them and subtracting it moves the good
readings off by as much as it moves the late ones on: the mean +3.0 +- 1.8 deg at the other
knob's -90 put development unit 1's right readings 3.6 deg short (docs/calibration.md, session
21). So each B offset is tested on the readings it was measured from: the mean absolute error
with it taken out must be smaller than without; else the sheet writes 0 there (its half-width
and half-cycles kept: what was measured). Not "smaller by more than its 95 % half-width": on
screwrod that dropped phi2's B_neg offset at the other knob's -90 deg (-1.69 +- 1.20, gain 0.79)
and development units 1-2 lost 3 of 112 values (104 -> 101, max 3.27 -> 3.78; session 22).
Whether an offset is then applied stays the calibration's decision
(:mod:`tsmd.calibration.reading_offset`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence

import numpy as np

from tsmd.profile.reading_offset import OffsetGrid, ReadingOffset

BACKLASHES = ("backlash_pos_deg", "backlash_neg_deg")

Readings = Mapping[tuple[int, float], Mapping[str, Sequence[float]]]
"""Per (knob, other-knob angle): each parameter's half-cycle errors, current minus tip (deg)."""


def offset_gain_deg(errors: Sequence[float], offset_deg: float) -> float:
    """How much taking ``offset_deg`` out of ``errors`` lowers their mean absolute value (deg;
    negative where it raises it; 0 without errors)."""
    e = np.asarray(errors, dtype=float)
    if e.size == 0:
        return 0.0
    return float(np.mean(np.abs(e)) - np.mean(np.abs(e - offset_deg)))


def helpful_grid(grid: OffsetGrid, errors: Sequence[Sequence[float]]) -> OffsetGrid:
    """``grid`` with its mean set to 0 at each angle where it does not lower the mean absolute
    error of that angle's ``errors``."""
    means = tuple(m if offset_gain_deg(e, m) > 0.0 else 0.0
                  for m, e in zip(grid.mean_deg, errors, strict=True))
    return dataclasses.replace(grid, mean_deg=means)


def helpful_offset(offset: ReadingOffset | None, knob: int,
                   readings: Readings) -> ReadingOffset | None:
    """One knob's offset with each backlash grid tested on its own readings
    (:func:`helpful_grid`); the dead-zone grids as measured."""
    if offset is None:
        return None
    grids = []
    for name, grid in offset.grids:
        if name in BACKLASHES:
            errors = [readings.get((knob, float(a)), {}).get(name, ())
                      for a in offset.other_knob_deg]
            grid = helpful_grid(grid, errors)
        grids.append((name, grid))
    return dataclasses.replace(offset, grids=tuple(grids))
