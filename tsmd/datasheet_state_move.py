"""How far the sheet unit's loaded lines move between its tracked sweep and its calibrated state.

The sheet's reference edges and points come from a tracked sweep of a fresh unit 0 (its first
minutes); a unit's edges come from its calibration, and the unit is used (and the tracking
bench scores it, session 27) in the state that calibration leaves. Where the catheter changes
over the calibration the tip's loaded line moves: warmgear's shaft warms and takes up slack
(unit 0's lines 1.4-2.0 deg of knob inward), cyclopebax's ropes take a set under the
calibration's loads (2.4 deg outward; session 28, docs/model.md). Every unit's calibrated
edges already carry that move, so drawing the plateau heights through the sheet unit's
calibrated edges (session 26) takes it out again, while the tracked edges keep it. Here the
move is measured on the sheet unit by its tip: the sheet's own sweep of each knob (other knob
at 0, one conditioning cycle) played once on a fresh unit and once on the unit as a calibration
left it; the knob angle where the analysed cycle's loaded branch crosses half its reach,
calibrated minus fresh, per side.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from simrig.plant import Plant
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.datasheet import ANALYSED_CYCLES, analysed_from, settle, tip_sweep
from tsmd.replay import run_trajectory

LINE_SPAN = (0.25, 0.75)
"""Share of the loaded branch's reach (from the tip's level where the knob passes 0 to the
amplitude's) fitted by a line of knob angle over tip angle: away from the knee and the turn."""


class KeptPlant:
    """A plant the rig's reset at the start of a run leaves as it is (the catheter stays
    inserted between its calibration and the next run); everything else is the wrapped one's."""

    def __init__(self, plant: Plant) -> None:
        self.plant = plant

    def reset(self) -> None:
        """Nothing: the state the calibration left is the one measured."""

    def step(self, dt_s: float, knob_deg: Any) -> Any:
        return self.plant.step(dt_s, knob_deg)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.plant, name)


def line_crossing_deg(pos_deg: ArrayLike, tip_deg: ArrayLike, side: int,
                      level_deg: float | None = None) -> tuple[float, float]:
    """(knob angle, tip level): where the loaded branch of ``side`` (+1: the knob moving up
    past 0, -1: down) crosses ``level_deg`` (None: half the branch's reach), from a line of
    knob over tip angle fitted between :data:`LINE_SPAN` of the reach (tracker noise averages)."""
    x = np.asarray(pos_deg, dtype=float)
    y = np.asarray(tip_deg, dtype=float)
    moving = np.gradient(x) * side > 0
    loaded = moving & (x * side > 0)
    if np.count_nonzero(loaded) < 10:
        raise ValueError(f"no loaded branch on side {side:+d}")
    xs, ys = x[loaded], y[loaded]
    start = float(np.median(ys[np.abs(xs) <= np.percentile(np.abs(xs), 5)]))
    end = float(np.median(ys[np.abs(xs) >= np.percentile(np.abs(xs), 95)]))
    lo, hi = sorted(start + f * (end - start) for f in LINE_SPAN)
    span = (ys >= lo) & (ys <= hi)
    if np.count_nonzero(span) < 5:
        raise ValueError(f"side {side:+d}: the tip does not move along its loaded branch")
    slope, icept = np.polyfit(ys[span], xs[span], 1)
    level = 0.5 * (start + end) if level_deg is None else float(level_deg)
    return float(slope * level + icept), level


def line_moves_deg(fresh: tuple[ArrayLike, ArrayLike], kept: tuple[ArrayLike, ArrayLike]
                   ) -> tuple[float, float]:
    """(pos side, neg side): how far the loaded line of ``kept`` lies from ``fresh``'s in knob
    degrees at the fresh branch's half reach (each a (knob, tip) pair of one analysed sweep);
    positive: the positive side's line moved outward, the negative side's inward."""
    moves = []
    for side in (1, -1):
        x_fresh, level = line_crossing_deg(*fresh, side)
        x_kept, _ = line_crossing_deg(*kept, side, level)
        moves.append(x_kept - x_fresh)
    return moves[0], moves[1]


def swept_tip(plant: Any, knob: int, seed: int, config: TsmdConfig,
              cycles: float = ANALYSED_CYCLES) -> tuple[np.ndarray, np.ndarray]:
    """(knob, tip) of the analysed cycles of the sheet's sweep of ``knob`` (other knob at 0)."""
    period_s = config.loop.period_s
    t, q, skip = settle(*tip_sweep(knob, 0.0, period_s, cycles), period_s)
    rec = run_trajectory(t, q, config=config, method="none", seed=seed, plant=plant)
    start = analysed_from(skip, period_s)
    return (np.asarray(rec[f"pos{knob + 1}"], float)[start:],
            np.asarray(rec[f"tip{knob + 1}"], float)[start:])


def state_moves_deg(plant_factory: Callable[[], Plant], calibrated: Plant, seed: int,
                    config: TsmdConfig | None = None, cycles: float = ANALYSED_CYCLES
                    ) -> tuple[tuple[float, float], ...]:
    """Per knob, (pos, neg) :func:`line_moves_deg` of the sheet unit as a calibration left it
    (``calibrated``, copied: not changed) against the unit built fresh (``cycles`` analysed
    after the conditioning one: the sheet's tracked sweep's by default)."""
    cfg = config if config is not None else default_sim_config()
    return tuple(line_moves_deg(swept_tip(plant_factory(), k, seed, cfg, cycles),
                                swept_tip(KeptPlant(copy.deepcopy(calibrated)), k, seed, cfg,
                                          cycles))
                 for k in (0, 1))
