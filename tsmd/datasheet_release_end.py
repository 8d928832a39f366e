"""The product's offset between the tip's release end and the current's, on the sheet's unit.

Method ours reads where each unit's release ends from the kink in its calibration current
(:mod:`tsmd.calibration.release_end`). That kink is not exactly where the tip reaches its
plateau (the current's low-pass lags, the ramp joins the flat gradually): on ratestate's
development units 1-4 it came 0.4-1.7 deg nearer the dead zone than the tip's end, the same way
on every side. The tracker on the sheet's unit measures that offset once per product, read the
way every unit's end is read: the sheet's unit calibrated by ``tsmd calibrate``'s own protocol
and sweeps (the rig's tracker recording the tip alongside), the current's end read from the
sweeps the fit sees, the tip's by the same kink fit on the same half-cycles; the offset (tip
minus current, away from the dead zone, mean of both sides) is
``reference_release_end_offset_deg``. Its presence in the sheet turns the reading on. (A
separate +-90 deg sweep with the other knob at 0 read the current's end 0.4-0.8 deg farther out
than the calibration's seven sweeps on the same unit: the offset belongs to the protocol.)
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence

import numpy as np

from simrig.plant import Plant
from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.release_end import read_release_end
from tsmd.calibration.tension_play_fit import SweepCurrent, sweeps_from_points
from tsmd.config import TsmdConfig
from tsmd.datasheet_unit_run import calibrate_sheet_unit
from tsmd.errors import TsmdError
from tsmd.profile import DeviceModel


def tip_sweeps(points: Sequence[GridPoint], knob: int) -> tuple[list[SweepCurrent],
                                                                list[SweepCurrent]]:
    """The fit's sweeps of ``knob`` and the same with the tracked tip in place of the current
    (truth, on the sheet's unit only)."""
    sweeps = sweeps_from_points(points, knob)
    mine = [p for p in points if p.knob == knob]
    tips = []
    for s, p in zip(sweeps, mine, strict=True):
        if p.recording is None or not p.recording.has_tip:
            raise TsmdError(f"release end: {p.name} has no tracked tip")
        rec = p.recording
        tips.append(dataclasses.replace(s, current_A=np.interp(
            s.t_s, np.asarray(rec["t"], float), np.asarray(rec[f"tip{knob + 1}"], float))))
    return sweeps, tips


def offset_deg(sweeps: Sequence[SweepCurrent], tips: Sequence[SweepCurrent]
               ) -> tuple[float, float] | None:
    """Tip's release end minus the current's, away from the dead zone, and the tip's plateau
    there (magnitude), each the mean of both sides (deg); None where either shows no end on a
    side."""
    offsets, plateaus = [], []
    for sign in (1, -1):
        by_current = read_release_end(sweeps, sign)
        by_tip = read_release_end(tips, sign)
        if by_current is None or by_tip is None:
            return None
        offsets.append(sign * (by_tip.end_deg - by_current.end_deg))
        plateaus.append(sign * by_tip.level)
    offset, plateau = float(np.mean(offsets)), float(np.mean(plateaus))
    return (offset, plateau) if math.isfinite(offset + plateau) else None


def measure_release_end_offsets(plant_factory: Callable[[], Plant], device: DeviceModel,
                                seed: int = 2000, config: TsmdConfig | None = None
                                ) -> tuple[tuple[float, float] | None, tuple[float, float] | None]:
    """Both knobs' (offset, plateau), from one calibration of the sheet's unit with ``device``
    (the sheet as measured so far: its backlash rule sets the window the end is read in)."""
    points = calibrate_sheet_unit(plant_factory, device, "release end", seed, config).points
    first, second = (offset_deg(*tip_sweeps(points, k)) for k in (0, 1))
    return first, second
