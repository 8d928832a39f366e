"""The loaded ramps' slope rise a sheath bend shows online, read on the data sheet's unit
(`tsmd datasheet --bend-relation --bend-slopes`).

Some products' bends move no dead-zone edge and still grow the backlash (the rate-and-state
plant, docs/online.md Sessions 21-22); what the current shows of such a bend under compensated
motion is the loaded ramps' slope rise on both tendons. The relation from that rise to beta
(:attr:`tsmd.online.bend.BendRelation.gain_per_slope`) is taken where the manufacturer measures
the other constants: the sheet's unit, driven with the online bench's mixed motion under its
straight calibration, the sheath bent at 80 s, and the rise read the way the online estimator
reads it in use (each knob's pooled slope change).
"""

from __future__ import annotations

from collections.abc import Callable
from statistics import mean
from typing import Any

from simrig.plant import Plant
from simrig.scenario import ShapeChange, ShapeChangePlant
from tsmd.datasheet_bend import BEND_SEED, ReadSlopes
from tsmd.online.rig_run import mixed_motion, run
from tsmd.profile import CatheterProfile, DeviceModel

BEND_AT_S = 80.0
"""When the sheath is bent in the reading run (the online bench's change time)."""
AFTER_S = 110.0
"""How long the reading run goes on after the bend (the online bench's)."""
MOTION_SEED = 0
"""The mixed motion's phases (the online bench's default seed)."""

def knob_slope_rises(worker: Any) -> tuple[float, float]:
    """Each knob's loaded-slope change at the end of a run: the mean over its two edges'
    pooled changes of both tendons' last ramps (:attr:`EdgeTracker.knob_change`)."""
    return (float(mean(worker.trackers[(0, s)].knob_change for s in (1, -1))),
            float(mean(worker.trackers[(1, s)].knob_change for s in (1, -1))))


def rig_slope_reader(factory: Callable[[], Plant], device: DeviceModel,
                     seed: int = BEND_SEED) -> ReadSlopes:
    """Slope rises of the simulated rig's plant, bent on demand, under ``device``'s sheet."""

    def read(straight: CatheterProfile, bend_deg: float) -> tuple[float, float]:
        plant = ShapeChangePlant(factory(), [ShapeChange(BEND_AT_S,
                                                         {"sheath_curvature_deg": bend_deg})])
        t, q = mixed_motion(BEND_AT_S + AFTER_S, MOTION_SEED)
        _, worker = run(straight, plant, t, q, True, seed, device)
        return knob_slope_rises(worker)

    return read


__all__ = ["AFTER_S", "BEND_AT_S", "MOTION_SEED", "knob_slope_rises", "rig_slope_reader"]
