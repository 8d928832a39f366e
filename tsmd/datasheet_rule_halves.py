"""The backlash rules scored half-cycle by half-cycle on the sheet's own unit.

A grid point's B is the median over its sweep's half-cycles, and the choice of rule
(:mod:`tsmd.datasheet_rule`) compared those medians with the tip. A rule whose ends fall on
either side of the tip's release (a gear's loaded steps read as the release on some
half-cycles, not on others) can still land a median near the tip on the sheet's unit and then
misread whole grid points on the next unit: warmgear unit 0 gave "line" 44/56 grid values
within 2 deg against "local" 43/56, while per half-cycle (plant alone, other knob 0/+90) "local"
placed 10/10 and 9/10 of B within 2 deg, "line" 2/10 and 0/10 (docs/calibration.md, session
20), and development units 1-2 under "line" were refused. So each rule is also scored on every
half-cycle after a reversal of its own calibration runs, against the tip tracked in the same
sweep, and the rules that misread the fewest (:attr:`HalfRead.misread`: B off by more than
the tip's own, another feature of the current taken for the release) are the candidates: in
the fast protocol a grid point's B per side is the median of two half-cycles, so one such
misread on a unit moves the value by half of it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.identify import resample_on_angle
from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.signal import lowpass
from tsmd.calibration.sweep_result import SweepResult
from tsmd.tip_truth import TIP_THRESHOLD_DEG

HALF_TARGET_DEG = 2.0
"""A half-cycle's B counts as placed within this of the tip's (the grid values' target)."""


def tip_backlash_deg(pos_deg: NDArray[np.float64], tip_deg: NDArray[np.float64],
                     direction: int, step_deg: float) -> float:
    """Knob travel from a half-cycle's reversal until the (low-passed) tip has moved the
    truth's threshold: the tip's B on that half-cycle, on the identification's angle grid; NaN
    where the tip never moves that far."""
    grid, tip_g = resample_on_angle(pos_deg, direction * tip_deg, direction, step_deg)
    if grid.size == 0:
        return math.nan
    moved = np.flatnonzero(tip_g - tip_g[0] > TIP_THRESHOLD_DEG)
    return float(grid[moved[0]] - grid[0]) if moved.size else math.nan


class HalfRead(NamedTuple):
    """One half-cycle after a reversal: B as the rule read it and as the tip shows it (deg)."""

    backlash_deg: float
    tip_deg: float

    @property
    def placed(self) -> bool:
        """Within :data:`HALF_TARGET_DEG` of the tip (a missing B is not)."""
        return abs(self.backlash_deg - self.tip_deg) <= HALF_TARGET_DEG

    @property
    def misread(self) -> bool:
        """Off by more than the tip's own B: the rule ended the backlash at another feature of
        the current (a gear's loaded step, 36-50 deg on warmgear), not near the release. A
        missing B is no misread: it leaves the grid point's median to the other half-cycles."""
        return abs(self.backlash_deg - self.tip_deg) > self.tip_deg


def half_cycle_reads(result: SweepResult, t_s: NDArray[np.float64],
                     tip_deg: NDArray[np.float64], step_deg: float) -> list[HalfRead]:
    """B by the rule and by the tip on each of the sweep's own half-cycles after a reversal
    (the tip as recorded at ``t_s``, low-passed as the truth reads it); half-cycles where the
    tip shows no B are left out (nothing to score)."""
    data = result.data
    tip_f, _ = lowpass(np.asarray(tip_deg, float), 1.0 / float(np.median(np.diff(t_s))))
    tip = np.interp(data.t_s, np.asarray(t_s, float), tip_f)
    out = []
    for h in result.data_half_cycles:
        if not h.after_reversal:
            continue
        truth = tip_backlash_deg(data.pos_deg[h.start:h.stop], tip[h.start:h.stop],
                                 h.direction, step_deg)
        if math.isfinite(truth):
            out.append(HalfRead(h.backlash_deg, truth))
    return out


def points_half_cycle_reads(points: Sequence[GridPoint], knob: int,
                            step_deg: float = IdentifyOptions().grid_step_deg
                            ) -> list[HalfRead]:
    """:func:`half_cycle_reads` over ``knob``'s grid points whose recording tracked the tip."""
    out: list[HalfRead] = []
    for p in points:
        rec = p.recording
        if p.knob != knob or rec is None or not rec.has_tip:
            continue
        out += half_cycle_reads(p.result, np.asarray(rec["t"], float),
                                np.asarray(rec[f"tip{knob + 1}"], float), step_deg)
    return out
