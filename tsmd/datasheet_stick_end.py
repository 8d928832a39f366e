"""The stick phase's end (:mod:`tsmd.calibration.stick_end`), chosen on the data sheet's unit.

Where a backlash reading lands on the tip's release only on average, each half-cycle's value
scatters about the tip's, and no offset takes that scatter out: it is what a unit's calibration
carries. A constant distance to the tip, on the other hand, is the product's reading offset,
which the sheet measures on the same unit and every unit subtracts
(:mod:`tsmd.datasheet_offset`). So the sheet's unit is calibrated with the fast protocol with
the sheet's rule as it stands and with the stick end, and each knob takes the stick end where
its backlash values scatter less about their own grid point's median distance to the tracked
tip (:func:`half_scatter_deg`); the reading offset and the rule's backlash gain are then
measured again under what was chosen (session 25: notchclutch unit 0, docs/calibration.md).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.estimate import RESOLUTION_DEG
from tsmd.calibration.protocol import fast_protocol
from tsmd.config import TsmdConfig
from tsmd.datasheet_offset import offset_readings, with_reading_offset, without_offset
from tsmd.datasheet_rule import Truth, rule_backlash_gain
from tsmd.profile import DeviceModel
from tsmd.tracked_calibration import ProtocolRun, play_protocol

BACKLASHES = ("backlash_pos_deg", "backlash_neg_deg")
MIN_SCATTER_GAIN_DEG = RESOLUTION_DEG
"""The stick end must lower the scatter by more than the identification's angle grid (a smaller
difference is below what one half-cycle's value resolves): notchclutch unit 0 1.40 -> 0.21 and
1.35 -> 0.14 deg; offline on one fast calibration of jawcrimp unit 0, phi2 0.14 -> 0.10 (kept
on its rule), lumped unit 0 0.36 -> 0.71 and 0.57 -> 1.09 (session 25)."""


@dataclass(frozen=True)
class StickChoice:
    """One knob: the backlash values' scatter about their grid points' offsets (deg, rms) with
    the sheet's rule and with the stick end, how many values, and what was chosen."""

    rule_deg: float
    stick_deg: float
    values: int
    chosen: bool

    def text(self) -> str:
        return (f"B scatter about the grid points' offsets {self.rule_deg:.2f} deg (the rule) / "
                f"{self.stick_deg:.2f} deg (stick end) over {self.values} values -> stick end "
                f"{'on' if self.chosen else 'off'}")


def with_stick_end(device: DeviceModel, on: tuple[bool, bool]) -> DeviceModel:
    """The sheet with the stick end on where ``on`` says (per knob; absent where off)."""
    return device.with_knob_flag("backlash_stick_end", on)


def half_scatter_deg(runs: Sequence[ProtocolRun], truth: Truth, knob: int) -> tuple[float, int]:
    """(rms, count) of ``knob``'s backlash values minus the tip's, each about the median of
    its own grid point and side (what a per-grid-point offset cannot take out)."""
    deviations: list[float] = []
    for (k, _), by_name in offset_readings(runs, truth, BACKLASHES, skip_unseen=True).items():
        if k != knob:
            continue
        for errors in by_name.values():
            e = np.asarray(errors, dtype=float)
            if e.size >= 2:
                deviations += list(e - float(np.median(e)))
    if not deviations:
        return math.nan, 0
    return float(np.sqrt(np.mean(np.square(deviations)))), len(deviations)


def stick_choice(rule: tuple[float, int], stick: tuple[float, int]) -> bool:
    """The stick end where its scatter is smaller by more than :data:`MIN_SCATTER_GAIN_DEG`
    (a closer call or a knob without readings keeps the rule)."""
    return bool(stick[1] and rule[1] and stick[0] < rule[0] - MIN_SCATTER_GAIN_DEG)


def choose_stick_end(config: TsmdConfig, device: DeviceModel, truth: Truth,
                     noise_seeds: Sequence[int],
                     truth_points: Sequence[GridPoint] | None = None
                     ) -> tuple[DeviceModel, tuple[StickChoice, StickChoice]]:
    """The sheet with each knob's stick-end choice on its own unit (``config.sim``) and the
    reading offset measured again under it (only where a knob took it: else the sheet as it
    was)."""
    plain = without_offset(with_stick_end(device, (False, False)))
    stick = without_offset(with_stick_end(device, (True, True)))
    rule_runs = [play_protocol(config, plain, fast_protocol(), s) for s in noise_seeds]
    stick_runs = [play_protocol(config, stick, fast_protocol(), s) for s in noise_seeds]
    choices = []
    for knob in (0, 1):
        a, b = half_scatter_deg(rule_runs, truth, knob), half_scatter_deg(stick_runs, truth, knob)
        choices.append(StickChoice(a[0], b[0], b[1], stick_choice(a, b)))
    on = (choices[0].chosen, choices[1].chosen)
    if not any(on):
        return device, (choices[0], choices[1])
    chosen = with_rule_gain(with_stick_end(device, on), stick_runs, on)
    # the rule gain moves no D or B value, so the stick-end runs are the offset's own
    made = (without_offset(chosen), stick_runs) if all(on) else None
    chosen, _ = with_reading_offset(chosen, config, truth, noise_seeds, truth_points, made)
    return chosen, (choices[0], choices[1])


def with_rule_gain(device: DeviceModel, runs: Sequence[ProtocolRun], on: tuple[bool, bool]
                   ) -> DeviceModel:
    """``reference_rule_backlash_gain`` read again where the stick end is on (each unit reads
    its own gain with B as the stick end reads it: the sheet's, read under the rule before,
    would move every unit's omega by the two readings' difference; mean over ``runs``, made
    under the stick end without an offset)."""
    knobs = []
    for knob, (k, o) in enumerate(zip(device.knobs, on, strict=True)):
        gains = [g for g in (rule_backlash_gain(r.points, knob) for r in runs) if g is not None]
        knobs.append(dataclasses.replace(k, reference_rule_backlash_gain=round(
            float(np.mean(gains)), 3)) if o and gains else k)
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))
