"""Whether the sheet's settle-rule backlash gain is read on its own unit as every unit reads it.

Each unit's omega weighs, among others, its settle-rule backlash gain against the sheet's
``reference_backlash_gain`` (:mod:`tsmd.calibration.unit_slope`). The sheet reads that gain on
its long tracked sweep (0.04 Hz, 24 cycles, the other knob at 0), a unit on its calibration's
sweeps (other speeds and amplitudes, smoothed over the other knob's grid). Where the settle
rule's backlash depends on how the knob is swept (notchclutch: a strain-rate stiffening braid
and a Stribeck drag), the two estimators differ on the same unit, and the reading moves every
unit's omega by that difference (notchclutch unit 0 read 0.95 / 0.91 of its own sheet's slope
on phi1 / phi2; docs/model.md, session 24 round 2). So the sheet's unit is calibrated as a
unit is, its settle gain read by the units' estimator, and where the slope ratio that reading
gives is not 1 within its own 95 % half-width the knob's units do not take the reading
(``settle_gain_read: false``; session 25).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tsmd.calibration.load_ramp import fit_sweep_sides
from tsmd.calibration.tension_play_fit import gain_reading, settle_rule_gains, sweeps_from_points
from tsmd.calibration.unit_slope import GainReading
from tsmd.profile import DeviceModel
from tsmd.tracked_calibration import ProtocolRun

Z95 = 1.96


@dataclass(frozen=True)
class SettleCheck:
    """One knob: the slope ratio its own settle reading gives on the sheet's unit (mean over
    the runs), that ratio's standard uncertainty, and whether the units keep the reading."""

    ratio: float
    sd: float
    readings: int
    kept: bool
    per_run: tuple[float, ...] = ()
    """Each run's slope ratio (printed: the runs of one unit differ by more than ``sd`` on
    notchclutch, docs/model.md session 25)."""

    def text(self) -> str:
        if not self.readings:
            return "no settle reading on the sheet's unit -> kept"
        return (f"settle gain read as a unit reads it: slope ratio {self.ratio:.3f} +- "
                f"{Z95 * self.sd:.3f} (95 %) over {self.readings} run(s) ("
                f"{', '.join(f'{r:.3f}' for r in self.per_run)}) -> "
                f"{'kept' if self.kept else 'not read by the units'}")


def settle_reading(points: Sequence[object], knob: int, sheet_gain: float) -> GainReading | None:
    """``knob``'s settle-rule gain reading on one calibration's grid points, as
    :func:`tsmd.calibration.tension_play_fit.loaded_slope` reads it (None where a sweep has no
    load ramp to fit)."""
    sweeps = sorted(sweeps_from_points(points, knob), key=lambda s: s.other_knob_deg)
    try:
        fits = [fit_sweep_sides(s.pos_deg, s.current_A, s.dead_zone_pos_deg, s.dead_zone_neg_deg,
                                s.backlash_pos_deg, s.backlash_neg_deg) for s in sweeps]
    except ValueError:
        return None
    pos, neg = settle_rule_gains(sweeps, [f[0] for f in fits], [f[1] for f in fits])
    return gain_reading(sheet_gain, [s.other_knob_deg for s in sweeps], pos, neg)


def settle_check(runs: Sequence[ProtocolRun], knob: int, sheet_gain: float) -> SettleCheck:
    """The sheet unit's runs' settle readings of ``knob``: kept where the ratio's mean is 1
    within :data:`Z95` times its uncertainty (the runs' mean standard uncertainty: one unit,
    the runs differ only in their noise)."""
    found = [r for r in (settle_reading(run.points, knob, sheet_gain) for run in runs
                         if run.points) if r is not None and math.isfinite(r.ratio())]
    if not found:
        return SettleCheck(math.nan, math.nan, 0, True)
    ratio = float(np.mean([r.ratio() for r in found]))
    sd = float(np.mean([r.ratio_sd() for r in found]))
    return SettleCheck(ratio, sd, len(found), bool(abs(ratio - 1.0) <= Z95 * sd),
                       tuple(r.ratio() for r in found))


def with_settle_check(device: DeviceModel, runs: Sequence[ProtocolRun]
                      ) -> tuple[DeviceModel, tuple[SettleCheck, SettleCheck]]:
    """The sheet with ``settle_gain_read: false`` on each knob whose settle reading does not
    hold on its own unit (``runs``: that unit's calibrations under the sheet); a knob without
    ``reference_backlash_gain`` is left as it is."""
    checks: list[SettleCheck] = []
    knobs = []
    for knob, k in enumerate(device.knobs):
        if k.reference_backlash_gain is None:
            checks.append(SettleCheck(math.nan, math.nan, 0, True))
            knobs.append(k)
            continue
        c = settle_check(runs, knob, float(k.reference_backlash_gain))
        checks.append(c)
        knobs.append(dataclasses.replace(k, settle_gain_read=None if c.kept else False))
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1])), (checks[0], checks[1])
