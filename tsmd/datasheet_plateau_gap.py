"""The sheet unit's dead-zone loop: its plateau gap and the flats per gap degree (session 25).

Each unit's calibration reads its plateau gap from the loop's motor current
(:mod:`tsmd.calibration.dead_zone_loop`); what a degree of gap is worth in tip flats is the
product's, measured here once on the sheet's unit with the tracker: the same loop move, read
from the current the way every unit's is (the sheet's own identification options), and the
tip's flats where each way in ends at 0 (the tip resting on that side's plateau), the move
played :data:`SHEET_REPEATS` times and pooled. The sheet
gets ``plateau_gap_deg`` (the gap) and ``plateau_gap_factor`` (both sides' flats, summed, over
the gap); their presence turns the loop on for the product. A knob whose loop shows no edge on
either side, or whose flats do not lie on both sides of 0, gets neither (and says so).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from simrig.plant import Plant
from tsmd.calibration.dead_zone_loop import LoopEdges, loop_move, read_loop_edges
from tsmd.calibration.identify import split_half_cycles
from tsmd.calibration.options import device_options
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.datasheet_unit_run import SHEET_UNIT_SEED
from tsmd.profile import DeviceModel
from tsmd.replay import LockstepRunner

FloatArray = NDArray[np.float64]

SHEET_REPEATS = 3
"""The sheet's unit plays each knob's loop move this many times, pooled: its gap is every
unit's reference, so its reading scatter would be every unit's bias (one move on snakedent's
unit 0 read phi2's gap 8.75 and 9.37 deg at two noise seeds)."""
LOOP_KEYS = ("plateau_gap_deg", "plateau_gap_factor")
"""The sheet's fields this stage writes (per knob); nothing else of the sheet depends on it."""


@dataclass(frozen=True)
class SheetLoop:
    """One knob's loop on the sheet's unit: the gap (current) and the tracked flats (deg)."""

    gap_deg: float
    flat_pos_deg: float
    flat_neg_deg: float

    @property
    def factor(self) -> float:
        """Both flats over the gap (NaN where the gap or a flat is missing or not positive)."""
        total = self.flat_pos_deg + self.flat_neg_deg
        ok = self.gap_deg > 0 and self.flat_pos_deg > 0 and self.flat_neg_deg > 0
        return total / self.gap_deg if ok and math.isfinite(total) else math.nan


def tracked_flats(cmd_deg: FloatArray, tip_deg: FloatArray,
                  min_reversal_deg: float = 10.0) -> tuple[float, float]:
    """(positive, negative) plateau (magnitudes, deg): the tip where each way in from a side's
    amplitude ends at 0, the mean over that side's ways in."""
    amplitude = float(np.max(np.abs(cmd_deg)))
    sides: dict[int, list[float]] = {1: [], -1: []}
    for direction, a, b, _ in split_half_cycles(cmd_deg, min_reversal_deg):
        start, stop = float(cmd_deg[a]), float(cmd_deg[b - 1])
        if abs(stop) < 0.5 * amplitude < abs(start):
            side = -direction  # coming down from +A ends on the positive plateau
            sides[side].append(side * float(tip_deg[b - 1]))
    pos, neg = (float(np.mean(sides[s])) if sides[s] else math.nan for s in (1, -1))
    return pos, neg


def measure_sheet_loops(plant_factory: Callable[[], Plant], device: DeviceModel,
                        seed: int = SHEET_UNIT_SEED, config: TsmdConfig | None = None
                        ) -> tuple[SheetLoop, SheetLoop]:
    """Both knobs' loop on the sheet's unit under ``device``'s identification options."""
    cfg = config if config is not None else default_sim_config()
    options = device_options(None, device)
    out = []
    with LockstepRunner(cfg, None, "none", seed, plant_factory()) as runner:
        for knob in (0, 1):
            edges, cmds, tips = [], [], []
            for _ in range(SHEET_REPEATS):
                move = loop_move(knob, runner.period_s)
                rec = runner.run(move.t_s, move.q_deg, False)
                k = knob + 1
                cmd = np.asarray(rec[f"cmd{k}"], float)
                edges.append(read_loop_edges(np.asarray(rec["t"], float), cmd,
                                             np.asarray(rec[f"pos{k}"], float),
                                             np.asarray(rec[f"cur{k}"], float), options[knob]))
                cmds.append(cmd)
                tips.append(np.asarray(rec[f"tip{k}"], float))
            pooled = LoopEdges(*(tuple(v for e in edges for v in getattr(e, f.name))
                                 for f in dataclasses.fields(LoopEdges)))
            pos, neg = tracked_flats(np.concatenate(cmds), np.concatenate(tips))
            out.append(SheetLoop(pooled.gap_deg, pos, neg))
    return out[0], out[1]


def with_plateau_gap(device: DeviceModel, config: TsmdConfig,
                     plant_factory: Callable[[], Plant], seed: int) -> DeviceModel:
    """The sheet with each knob's ``plateau_gap_deg`` and ``plateau_gap_factor`` (both or
    neither, per knob)."""
    t0 = time.monotonic()
    loops = measure_sheet_loops(plant_factory, device, seed, config)
    knobs = []
    for name, k, loop in zip(("phi1", "phi2"), device.knobs, loops, strict=True):
        factor = loop.factor
        if math.isfinite(factor):
            knobs.append(dataclasses.replace(k, plateau_gap_deg=round(loop.gap_deg, 2),
                                             plateau_gap_factor=round(factor, 3)))
            print(f"  {name} dead-zone loop: gap {loop.gap_deg:.2f} deg, tip flats "
                  f"{loop.flat_pos_deg:.2f} / {loop.flat_neg_deg:.2f} deg, factor {factor:.3f}")
        else:
            knobs.append(k)
            print(f"  {name} dead-zone loop: not read (gap {loop.gap_deg:.2f} deg, flats "
                  f"{loop.flat_pos_deg:.2f} / {loop.flat_neg_deg:.2f}): no field")
    print(f"  dead-zone loop: {time.monotonic() - t0:.0f} s")
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))
