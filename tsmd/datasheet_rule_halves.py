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
sweep: a reading that carries across the unit's half-cycles is what carries to other units.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

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


def half_cycle_errors(result: SweepResult, t_s: NDArray[np.float64],
                      tip_deg: NDArray[np.float64], step_deg: float) -> list[float]:
    """Identified minus tip B on each of the sweep's own half-cycles after a reversal (the tip
    as recorded at ``t_s``, low-passed as the truth reads it); NaN where the rule gave no B
    (a miss) and left out where the tip shows no B (nothing to score)."""
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
            out.append(h.backlash_deg - truth)
    return out


def points_half_cycle_errors(points: Sequence[GridPoint], knob: int,
                             step_deg: float = IdentifyOptions().grid_step_deg) -> list[float]:
    """:func:`half_cycle_errors` over ``knob``'s grid points whose recording tracked the tip."""
    out: list[float] = []
    for p in points:
        rec = p.recording
        if p.knob != knob or rec is None or not rec.has_tip:
            continue
        out += half_cycle_errors(p.result, np.asarray(rec["t"], float),
                                 np.asarray(rec[f"tip{knob + 1}"], float), step_deg)
    return out


def placed(errors: Sequence[float]) -> int:
    """How many half-cycles' B lie within :data:`HALF_TARGET_DEG` of the tip (a NaN is not)."""
    e = np.asarray(errors, dtype=float)
    return int(np.sum(np.abs(e[np.isfinite(e)]) <= HALF_TARGET_DEG))
