"""The recovery rule's sheet constants, measured on the data sheet's tracked unit (session 16).

The rule "recovery" (:mod:`tsmd.calibration.recovery`, a self-locking handle) ends B at the
current's recovery from its post-reversal overshoot plus a per-product lag, and where no
half-cycle shows the recovery it gives the sheet's reference backlash scaled by the unit's
current swing and a bend gain at the other knob's +-90 deg. Both constants are the
manufacturer's: its unit is calibrated with the fast protocol from its current alone, as every
unit is, under the rule with no lag; each half-cycle that shows its recovery gives the tip's B
minus its end (one reading of the lag, the median over them is the sheet's), and each grid point
gives the tip's B and the current's swing there (:func:`tsmd.calibration.recovery.bend_gain`,
the mean of both sides). Measured as a candidate before the rule choice
(:mod:`tsmd.datasheet_rule` offers "recovery" only to a knob with a lag) and kept only on a
knob whose chosen rule is "recovery".
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from tsmd.calibration.protocol import fast_protocol
from tsmd.calibration.recovery import bend_gain
from tsmd.config import TsmdConfig
from tsmd.datasheet_offset import offset_readings
from tsmd.datasheet_rule import Truth
from tsmd.profile import DeviceKnob, DeviceModel
from tsmd.profile.sheet_schema import OPTIONAL_KNOB_RANGES
from tsmd.tracked_calibration import ProtocolRun, play_protocol

BACKLASHES = ("backlash_pos_deg", "backlash_neg_deg")


def probe_sheet(device: DeviceModel) -> DeviceModel:
    """The sheet with rule "recovery" and no lag, bend gain or reading offset on every knob:
    what the unit is calibrated with to read the recovery's ends."""
    knobs = tuple(dataclasses.replace(k, backlash_release_rule="recovery",
                                      backlash_recovery_lag_deg=0.0, backlash_bend_gain=None,
                                      reading_offset=None) for k in device.knobs)
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def recovery_lags(runs: Sequence[ProtocolRun], truth: Truth) -> tuple[float | None, ...]:
    """Per knob: the median over every half-cycle that shows its recovery (runs with no lag)
    of the tip's B minus the value read; None for a knob where none shows it."""
    readings = offset_readings(runs, truth, BACKLASHES, skip_unseen=True)
    lags: list[list[float]] = [[], []]
    for (knob, _), by_name in readings.items():
        for name in BACKLASHES:
            lags[knob] += [-d for d in by_name[name]]
    return tuple(float(np.median(x)) if x else None for x in lags)


def bend_gains(runs: Sequence[ProtocolRun], truth: Truth, device: DeviceModel
               ) -> tuple[float | None, ...]:
    """Per knob: the tip's B over the swing law's at the other knob's +-90 deg over the same at
    0 (:func:`tsmd.calibration.recovery.bend_gain` against the sheet's reference backlash and
    swing), the mean of both sides; None where a side or the reference lacks it."""
    out: list[float | None] = []
    for knob, k in enumerate(device.knobs):
        gains = []
        for name, ref in zip(BACKLASHES, (k.reference_backlash_pos_deg,
                                          k.reference_backlash_neg_deg), strict=True):
            points = []
            for run in runs:
                for p in run.points:
                    tip = truth.get((p.knob, float(p.other_deg)))
                    swings = [h.release_swing_A for h in p.result.half_cycles
                              if h.backlash_name == name and math.isfinite(h.release_swing_A)]
                    if p.knob == knob and tip is not None and swings:
                        points.append((float(p.other_deg), tip[name], float(np.median(swings))))
            swing = k.reference_release_swing_A
            if ref is not None and swing is not None and swing > 0.0:
                gains.append(bend_gain(points, ref, swing))
        finite = [g for g in gains if math.isfinite(g)]
        out.append(float(np.mean(finite)) if len(finite) == 2 else None)
    return tuple(out)


def _in_range(name: str, value: float | None) -> float | None:
    """``value`` where the sheet's schema reads it back, else None (no candidate)."""
    lo, hi, _unit = OPTIONAL_KNOB_RANGES[name]
    return value if value is not None and math.isfinite(value) and lo <= value <= hi else None


def with_recovery_constants(device: DeviceModel, config: TsmdConfig, truth: Truth,
                            noise_seeds: Sequence[int]
                            ) -> tuple[DeviceModel, list[ProtocolRun]]:
    """The sheet with each knob's ``backlash_recovery_lag_deg`` and ``backlash_bend_gain``
    from fast calibrations of its own unit (``config.sim``) under the rule with no lag (none
    where unmeasured or outside the schema's range: the knob then offers no "recovery"); its
    rules are unchanged."""
    probe = probe_sheet(device)
    runs = [play_protocol(config, probe, fast_protocol(), seed) for seed in noise_seeds]
    lags, gains = recovery_lags(runs, truth), bend_gains(runs, truth, device)
    knobs = []
    for k, lag, gain in zip(device.knobs, lags, gains, strict=True):
        lag = _in_range("backlash_recovery_lag_deg", None if lag is None else round(lag, 2))
        gain = _in_range("backlash_bend_gain", None if gain is None else round(gain, 3))
        knobs.append(dataclasses.replace(k, backlash_recovery_lag_deg=lag,
                                         backlash_bend_gain=gain if lag is not None else None))
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1])), runs


def recovery_where_chosen(device: DeviceModel) -> DeviceModel:
    """The sheet without the recovery rule's constants on a knob whose rule is another."""
    def kept(k: DeviceKnob) -> DeviceKnob:
        if k.backlash_release_rule == "recovery":
            return k
        return dataclasses.replace(k, backlash_recovery_lag_deg=None, backlash_bend_gain=None)

    return dataclasses.replace(device, knobs=(kept(device.knobs[0]), kept(device.knobs[1])))
