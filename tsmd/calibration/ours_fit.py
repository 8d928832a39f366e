"""Our compensator's extra parameters, fitted by the model's own function on the same sweeps.

The fitting itself belongs to the compensation package (``tsmd.compensation.ours``); the
calibration hands it the current-only sweep arrays and what the paper's identification found.
"""

from __future__ import annotations

from collections.abc import Sequence

from tsmd.calibration.assemble import GridPoint
from tsmd.compensation.ours import OursParams, SweepData, fit_ours_knob
from tsmd.profile import DeviceModel


def fit_ours_for_knob(points: Sequence[GridPoint], device: DeviceModel, knob: int
                      ) -> OursParams:
    """``tsmd.compensation.ours.fit_ours_knob`` on the current-only data of the sweeps."""
    sweeps = []
    for p in sorted(points, key=lambda q: q.other_deg):
        d = p.result.data
        sweeps.append(SweepData(
            t_s=d.t_s, cmd_deg=d.cmd_deg, pos_deg=d.pos_deg, current_A=d.current_A,
            other_knob_deg=float(p.other_deg),
            dead_zone_pos_deg=p.result.estimate("dead_zone_pos_deg"),
            dead_zone_neg_deg=p.result.estimate("dead_zone_neg_deg"),
            backlash_pos_deg=p.result.estimate("backlash_pos_deg"),
            backlash_neg_deg=p.result.estimate("backlash_neg_deg")))
    return fit_ours_knob(sweeps, device.knobs[knob])
