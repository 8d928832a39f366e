"""The product's reading offset applied to a sweep's values (session 14).

The data sheet measures, on its tracked unit, what the current reads minus what the tip shows
per parameter and other-knob angle (:mod:`tsmd.profile.reading_offset`). Where that offset is
a product's bias (twistshaft's B at the other knob's +-90 deg, screwrod's B), every unit of the
product reads off by about as much in every half-cycle, and subtracting it moves the values
onto the tip. Where it is not sure it is noise of one unit, and subtracting it would carry
unit 0's noise into every unit: such an offset is not applied (shrunk to nothing). An applied
offset brings its own uncertainty, which the gate adds to the half-cycles'
(:class:`tsmd.calibration.estimate.Estimate`).

Two frames (session 26, round 2): the reported D/B take every sure offset however small; our
compensator's fit reads its sweeps with the offsets of 1 deg and more only, as the data sheet's
reference edges, knees and gains were read against. Applying the sub-degree ones there too moved
the fit's release zero-loads (warmgear development 2 phi1's negative side by 3 deg) and cost
tracking in 11 of 11 rows (docs/calibration.md, "Session 26 (branch s26-calib)", "Round 2").
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from tsmd.calibration.play_engage import engage, engage_lag_deg
from tsmd.calibration.sweep_result import SweepResult
from tsmd.profile.reading_offset import OffsetGrid, ReadingOffset

MODEL_MIN_OFFSET_DEG = 1.0
"""Our compensator's frame: an offset below this is not applied to the sweeps its fit reads (nor
to the sheet's reference edges, knees and gains compared with them)."""
REPORT_MIN_OFFSET_DEG = 0.0
"""The reported D/B: every sure offset is applied (sub-degree ones moved warmgear 1-4 215 ->
224/224 and 101-104 219 -> 223/224 within 2 deg)."""
MIN_OFFSET_U95_RATIO = 1.0
"""An offset is applied only where it exceeds its own 95 % half-width this many times (its
interval excludes zero): one measured inconsistently over the sheet unit's half-cycles is not."""


def applied_deg(grid: OffsetGrid, min_deg: float = MODEL_MIN_OFFSET_DEG
                ) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Per other-knob angle: (offset applied, its 95 % half-width); 0, 0 where not applied
    (not sure, or below ``min_deg``)."""
    shift, u95 = [], []
    for m, u in zip(grid.mean_deg, grid.u95_deg, strict=True):
        use = abs(m) >= min_deg and abs(m) > MIN_OFFSET_U95_RATIO * u
        shift.append(m if use else 0.0)
        u95.append(u if use else 0.0)
    return tuple(shift), tuple(u95)


def offset_at(offset: ReadingOffset, name: str, other_deg: float,
              min_deg: float = MODEL_MIN_OFFSET_DEG) -> tuple[float, float]:
    """(offset to subtract, its 95 % half-width) of ``name`` with the other knob at
    ``other_deg``: linear between the sheet's angles, held beyond them."""
    grid = offset.grid(name)
    if grid is None:
        return 0.0, 0.0
    shift, u95 = applied_deg(grid, min_deg)
    at = np.asarray(offset.other_knob_deg, dtype=float)
    return (float(np.interp(other_deg, at, np.asarray(shift))),
            float(np.interp(other_deg, at, np.asarray(u95))))


def left_u95_deg(offset: ReadingOffset | None, name: str, other_deg: float,
                 min_deg: float = MODEL_MIN_OFFSET_DEG) -> float:
    """The bias an offset the sheet measured but :func:`applied_deg` does not apply leaves in
    ``name``'s values, as a 95 % bound: |mean| + its half-width per sheet angle (0 where the
    offset is applied: its half-width goes to the gate instead), linear between the angles,
    held beyond them; 0 without a measured offset. Session 27: wormeyelet's B offsets (unsure,
    +0.46 +- 0.52 deg and the like) were neither subtracted nor counted, and its B half-widths
    of 0.4-1.1 deg covered development units 1-2 15/24."""
    grid = None if offset is None else offset.grid(name)
    if offset is None or grid is None:
        return 0.0
    shift, _ = applied_deg(grid, min_deg)
    left = [0.0 if s != 0.0 else abs(m) + u
            for s, m, u in zip(shift, grid.mean_deg, grid.u95_deg, strict=True)]
    return float(np.interp(other_deg, np.asarray(offset.other_knob_deg, dtype=float),
                           np.asarray(left)))


def reference_edge_deg(offset: ReadingOffset | None, name: str,
                       edge_deg: float | None) -> float | None:
    """A data sheet's reference dead-zone edge (read from current on its unit, other knob at 0)
    corrected like every unit's edge, so that the plateau heights built on it and the unit's
    corrected edges describe the same line (uncorrected, the loaded line moves by the offset)."""
    if offset is None or edge_deg is None:
        return edge_deg
    return float(edge_deg) - offset_at(offset, name, 0.0)[0]


def calibrated_edges(device_knob: Any, edge_pos_deg: float, edge_neg_deg: float
                     ) -> tuple[float, float]:
    """The sheet unit's edges the plateau heights are drawn through: those its own calibration
    read (``calibrated_dead_zone_*_deg``, already corrected, session 26) where the sheet has
    both, else ``edge_*_deg`` as given. A unit's edge moves its loaded line by its difference
    from the sheet unit's, so both must be read the same way: on warmgear the tracked sweep's
    edges (the unit's first minutes) lay 1.3-3.2 deg outside what the calibration, minutes
    later with the shaft warm, read on the same unit."""
    pos = getattr(device_knob, "calibrated_dead_zone_pos_deg", None)
    neg = getattr(device_knob, "calibrated_dead_zone_neg_deg", None)
    if pos is None or neg is None:
        return edge_pos_deg, edge_neg_deg
    return float(pos), float(neg)


def corrected(result: SweepResult, offset: ReadingOffset | None,
              other_deg: float, release_slope: float | None = None,
              min_deg: float = MODEL_MIN_OFFSET_DEG, read_play: bool = True) -> SweepResult:
    """``result`` with every half-cycle's value moved by the product's offset at this grid
    point (those of ``min_deg`` and more), and the offsets' half-widths kept for the gate
    (unchanged without an offset), the half-widths of the backlashes the current does not show
    (``result.unseen``) with them."""
    values = dict(result.values)
    # A backlash the current does not show is the sheet's, not a reading: no offset, and its
    # own half-width goes to the gate in the offset's place.
    u95: dict[str, float] = dict(result.unseen)
    shifts: dict[str, float] = {}
    for name, v in result.values.items():
        shift, u = (0.0, 0.0) if offset is None else offset_at(offset, name, other_deg, min_deg)
        if shift != 0.0 and name not in result.unseen:
            values[name] = tuple(x - shift for x in v)
            u95[name] = u
            shifts[name] = shift
    if not u95:
        return result
    # a handle's play whose end the current shows: the unit's own reading (session 24), past
    # the line rule's end only (``read_play``: a stick end's offset is no play, session 27)
    plays = {name: offset_at(offset, name, 0.0, min_deg)[0] for name in shifts
             if name.startswith("backlash")} if offset is not None and read_play else {}
    read = engage(result, shifts, plays, engage_lag_deg(release_slope))
    values.update(read.values)
    return dataclasses.replace(result, values=values, offset_u95_deg=u95,
                               own_offset_deg=read.own, play_ends_deg=read.ends)
