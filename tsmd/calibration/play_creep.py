"""A tip that creeps while a handle's play opens, as the play's end shows it (session 25).

Where the backlash is read at the end of the handle's play (:mod:`tsmd.calibration.play_engage`),
the reading assumes the tip holds until the far flanks meet. On some units it does not: the
rope, held on the drum only by the drum's bearing while the play opens, pays out as the
section's bend gives way, and the tip creeps back by a degree or more long before the play
closes (planetwist development units 1, 6, 7; sample units 201, 202, 207). The current shows
nothing of the creep itself (the drum floats: no torque reaches the knob), but the rope the drum
paid out must be wound back before the far flanks meet, so the play closes *later* than a rigid
tooth clearance would, by as much as the tip crept, and the creep depends on the rope's load
(the other knob's angle, the side). A rigid play closes at one knob travel after every
reversal; on a creeping unit the end moves over the grid, or lies beyond where the sheet's play
should close (no step found there). So where a knob's play ends spread more than
:data:`CREEP_SPREAD_DEG` over its grid points and sides (the latest end of each), or more
than :data:`MISSING_SHARE` of its half-cycles show no step, or (session 26) the two sides of
one grid point close more than :data:`SIDE_GAP_DEG` apart, the knob's B is flagged: its reported
95 % half-width grows to reach back to the swing's end (where a creeping tip has already started
back), and a one-line warning names the knob.

Session 27: on a flagged knob B is also re-read where the creep shows. Each grid point's side
whose play closed more than :data:`CREEP_DELAY_DEG` after the knob's earliest close (or never
closed within the sheet's window) carried rope its tip paid out: there the tip let go near the
swing's end (planetwist development 1, 6, 7 and sample 201, 202, 207: the tip's 1 deg
threshold 0-1.3 deg from the knob's earliest line end, 9-16 deg before the play's end), so its
B is read at the swing's end. The sides that closed with the earliest keep the play's end (a
creeping knob's holding side, development 1 phi2 B_pos, let go at the play's end). Only the
reported values move: our compensator's fit keeps the frame it was read in.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tsmd.calibration.assemble import KNOB_LABELS, GridPoint, QualityReport
from tsmd.calibration.signal import FloatArray
from tsmd.calibration.sweep_result import SweepResult

CREEP_SPREAD_DEG = 1.5
"""Largest spread of a knob's play ends (per grid point and side the latest of its half-cycles)
a rigid play shows. Planetwist, noise seed 0: holding knobs 0.10-0.59 deg (fast protocol,
development 1-8, held out 101-104, sample 201-208; paper protocol, development 2: 0.24 / 0.31),
creeping knobs 2.15-4.88. The latest, not the median: a rigid play can close early in one
half-cycle (not yet fully open at a sweep's first reversal: development 2, paper protocol, phi2
at phi1 +90 10.35 against 12.55 deg, its median over two half-cycles pulling the spread to 1.10),
never later than the swing and the clearance; a creep only delays it."""
MISSING_SHARE = 0.25
"""A knob where more than this share of the half-cycles show no step where the sheet's play
should close (within :data:`tsmd.calibration.play_engage.ENGAGE_WINDOW` of it) is flagged as
well: its play closed later than the window (development unit 6's phi2: 11 of 16)."""
SIDE_GAP_DEG = 0.75
"""Largest difference between the two sides' play ends (each the latest of its half-cycles) at
one grid point a rigid play shows (session 26). The carrier crosses the same tooth clearance
after either reversal, and what the grid point does to both sides (the other knob's coupling:
a rigid play closes 0.1-0.2 deg later at +-90 than at 0) cancels in the difference, while a
creep, which grows with the loaded rope's tension, delays mostly one side. Planetwist, fast
protocol, noise seed 0, the largest difference per knob: holding knobs 0.02-0.38 deg
(development 1-8, sample 201-208; paper protocol, development 2: 0.26), knobs whose creep
delays one side 1.14-3.16 (development 1 phi2, sample 201, 202, 207 phi1); the limit lies
between. A creep delaying both sides alike (development 7 phi1: 0.09) shows in the spread."""
CREEP_DELAY_DEG = SIDE_GAP_DEG
"""On a flagged knob, a grid point's side whose play closed more than this after the knob's
earliest close is re-read at the swing's end (session 27). A rigid play's latest ends over one
knob's grid points and sides lie within 0.10-0.59 deg of each other (planetwist, holding knobs,
development 1-8, sample 201-208), within :data:`SIDE_GAP_DEG` as the two sides of one grid
point do; a creeping side closed 0.9-2.8 deg after its knob's earliest (development 1 phi2 B_neg,
sample 207 phi1 B_pos at the other knob's 0)."""
REACH_MARGIN_DEG = 2.0
"""The widened half-width reaches this far before the swing's end (the line rule's earliest
end over the knob's grid, :func:`earliest_line_end_deg`): a creeping tip starts back at the
reversal, so its 1 deg threshold can fall before that end (development units 1, 6, 7: up to
1.2 deg before the grid point's own earliest line end)."""


@dataclass(frozen=True)
class PlayCreep:
    """One knob's play ends over its grid: their spread, the largest gap between the two sides
    at one grid point, and how many half-cycles showed none."""

    knob: int
    low_deg: float
    high_deg: float
    missing: int
    half_cycles: int
    side_gap_deg: float = 0.0

    @property
    def spread_deg(self) -> float:
        return self.high_deg - self.low_deg if self.high_deg >= self.low_deg else 0.0

    def rigid(self, spread_limit_deg: float = CREEP_SPREAD_DEG) -> bool:
        """Whether the play closed at one travel in (nearly) every half-cycle."""
        return (self.spread_deg <= spread_limit_deg
                and not self.side_gap_deg > SIDE_GAP_DEG
                and self.missing <= MISSING_SHARE * self.half_cycles)


def _finite(values: Sequence[float]) -> FloatArray:
    v = np.asarray(values, dtype=float)
    return v[np.isfinite(v)]


def play_creep(points: Sequence[GridPoint], knob: int) -> PlayCreep | None:
    """``knob``'s play ends over its grid points and sides (the latest per grid point and side);
    None where its backlash was not read at a play's end (the sheet announces none)."""
    latest: dict[tuple[float, str], float] = {}
    missing, total = 0, 0
    for p in points:
        if p.knob != knob:
            continue
        for name, ends in p.result.play_ends_deg.items():
            found = _finite(ends)
            total += len(ends)
            missing += len(ends) - found.size
            if found.size:
                key = (float(p.other_deg), name)
                latest[key] = max(latest.get(key, -math.inf), float(found.max()))
    if total == 0:
        return None
    closed = list(latest.values())
    low, high = (min(closed), max(closed)) if closed else (math.nan, math.nan)
    return PlayCreep(knob, low, high, missing, total, side_gap_deg(latest))


def side_gap_deg(latest: dict[tuple[float, str], float]) -> float:
    """The largest difference between the two backlashes' latest play ends at one grid point
    (0 where no grid point has both)."""
    gaps = [abs(end - latest[(other, "backlash_neg_deg")])
            for (other, name), end in latest.items()
            if name == "backlash_pos_deg" and (other, "backlash_neg_deg") in latest]
    return max(gaps, default=0.0)


def earliest_line_end_deg(points: Sequence[GridPoint], knob: int) -> float:
    """The earliest line-rule end of ``knob``'s play-end backlashes over its whole grid (the
    swing's end: the drive train's, the same at every grid point, while one half-cycle's line
    end scatters by a few degrees: sample unit 201 phi1 2.75-8.0); NaN without one."""
    lines = _finite([h.backlash_deg for p in points if p.knob == knob
                     for h in p.result.half_cycles if h.backlash_name in p.result.play_ends_deg])
    return float(lines.min()) if lines.size else math.nan


def reach_deg(result: SweepResult, name: str, line_end_deg: float) -> float:
    """How far before ``name``'s value the tip may let go on a creeping unit: down to the
    swing's end ``line_end_deg`` less :data:`REACH_MARGIN_DEG`; 0 without a value or line end."""
    value = _finite(result.values.get(name, ()))
    if not value.size or not math.isfinite(line_end_deg):
        return 0.0
    return max(0.0, float(np.median(value)) - line_end_deg + REACH_MARGIN_DEG)


def widened(result: SweepResult, line_end_deg: float) -> SweepResult:
    """``result`` with each play-end backlash's reported half-width at least its
    :func:`reach_deg` (:attr:`SweepResult.product_u95_deg`, which the gate does not judge)."""
    more = {name: max(result.unit_u95_deg(name), reach_deg(result, name, line_end_deg))
            for name in result.play_ends_deg}
    if not more:
        return result
    return dataclasses.replace(result, product_u95_deg={**result.product_u95_deg, **more})


def creeping_sides(points: Sequence[GridPoint], knob: int) -> set[tuple[float, str]]:
    """``knob``'s (other-knob angle, backlash) whose play closed more than
    :data:`CREEP_DELAY_DEG` after the knob's earliest close over its grid, or whose half-cycles
    all showed no step (the play closed beyond the sheet's window)."""
    latest: dict[tuple[float, str], float] = {}
    for p in points:
        if p.knob != knob:
            continue
        for name, ends in p.result.play_ends_deg.items():
            found = _finite(ends)
            key = (float(p.other_deg), name)
            latest[key] = max(latest.get(key, -math.inf),
                              float(found.max()) if found.size else math.inf)
    closed = [end for end in latest.values() if math.isfinite(end)]
    if not closed:
        return set(latest)
    earliest = min(closed)
    return {key for key, end in latest.items() if end > earliest + CREEP_DELAY_DEG}


def reread_at_swing_end(result: SweepResult, names: set[str], line_end_deg: float
                        ) -> SweepResult:
    """``result`` with the backlashes ``names`` moved so that their robust mean is the swing's
    end ``line_end_deg`` (each half-cycle by the same shift: their scatter, which the gate's
    pool reads, is kept)."""
    values = dict(result.values)
    for name in names:
        v = np.asarray(values.get(name, ()), dtype=float)
        if v.size and math.isfinite(line_end_deg):
            values[name] = tuple(float(x) for x in v - (result.estimate(name) - line_end_deg))
    return dataclasses.replace(result, values=values)


def reread_creeping(points: list[GridPoint], knob: int, line_end_deg: float) -> int:
    """On a flagged ``knob``: each creeping side's B (:func:`creeping_sides`) re-read at the
    swing's end, in ``points`` in place (the compensator's frame, ``model_result``, kept as it
    was read); how many sides were re-read."""
    sides = creeping_sides(points, knob)
    count = 0
    for i, p in enumerate(points):
        names = {name for (other, name) in sides
                 if p.knob == knob and other == float(p.other_deg) and p.result.values.get(name)}
        if not names:
            continue
        model = p.model_result if p.model_result is not None else p.result
        points[i] = dataclasses.replace(p, result=reread_at_swing_end(p.result, names,
                                                                      line_end_deg),
                                        model_result=model)
        count += len(names)
    return count


def check_play_creep(points: list[GridPoint], report: QualityReport,
                     spread_limit_deg: float = CREEP_SPREAD_DEG) -> None:
    """Per knob whose play did not close at one travel: a one-line warning, and (in
    ``points``, in place) its creeping sides' B re-read at the swing's end
    (:func:`reread_creeping`) and every play-end B's reported half-width widened to reach back
    to it; each knob's spread in ``report.figures``."""
    for knob in (0, 1):
        creep = play_creep(points, knob)
        if creep is None:
            continue
        label = KNOB_LABELS[knob]
        report.figures[f"{label}_play_end_spread_deg"] = creep.spread_deg
        report.figures[f"{label}_play_end_side_gap_deg"] = creep.side_gap_deg
        if creep.rigid(spread_limit_deg):
            continue
        line = earliest_line_end_deg(points, knob)
        reread = reread_creeping(points, knob, line)
        report.figures[f"{label}_backlash_reread_sides"] = reread
        reach = 0.0
        for i, p in enumerate(points):
            if p.knob == knob:
                points[i] = dataclasses.replace(p, result=widened(p.result, line))
                reach = max([reach, *(reach_deg(p.result, n, line)
                                      for n in p.result.play_ends_deg)])
        where = (f"the play closes {creep.low_deg:.1f}-{creep.high_deg:.1f} deg after a reversal "
                 f"over the grid (spread {creep.spread_deg:.1f} deg; a rigid play closes at one "
                 "travel)" if math.isfinite(creep.spread_deg) and creep.high_deg > creep.low_deg
                 else "")
        if creep.side_gap_deg > SIDE_GAP_DEG:
            where += ("; " if where else "") + (
                f"its two sides close {creep.side_gap_deg:.1f} deg apart at one grid point")
        if creep.missing > MISSING_SHARE * creep.half_cycles:
            where += ("; " if where else "") + (
                f"no step where the play should close in {creep.missing} of "
                f"{creep.half_cycles} half-cycles")
        report.warnings.append(
            f"{label}: backlash unsure, the tip may creep while the handle's play opens: "
            f"{where}; B re-read at the swing's end ({line:.1f} deg) on {reread} grid-point "
            f"side(s) whose play closed late; the tip may let go up to {reach:.1f} deg before "
            "B says, B's 95 % half-width widened to cover it")


__all__ = ["CREEP_DELAY_DEG", "CREEP_SPREAD_DEG", "MISSING_SHARE", "REACH_MARGIN_DEG",
           "SIDE_GAP_DEG", "PlayCreep", "check_play_creep", "creeping_sides",
           "earliest_line_end_deg", "play_creep", "reach_deg", "reread_at_swing_end",
           "reread_creeping", "side_gap_deg", "widened"]
