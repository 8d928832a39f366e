"""The loaded-branch templates over the other knob's angle, measured on the data sheet's unit.

Where both planes bend one shared part (a superelastic spine that transforms under the combined
bend), the other plane's bend changes a knob's loaded branch: on the nitinol plant's unit 0 the
knee (tip 0.53 knob deg per deg past the edge, then 1.05) is there with the other knob within
+-30 deg and gone at +-60 and +-90 (about 0.9 and 0.97 throughout). The current cannot show the
tip's shape (docs/model.md, session 9), so the templates are a product constant: each knob swept
+-90 deg at the sheet's 0.04 Hz with the other knob held at each angle of the calibration grid,
the template read as the sheet's own (:func:`tsmd.datasheet_shape.measure_loaded_shape`) from
the current's edges on that sweep and the sheet's omega.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from simrig.plant import Plant
from tsmd.calibration.identify import identify_sweep
from tsmd.compensation.grid import CALIBRATION_GRID_DEG
from tsmd.compensation.loaded_shape import LoadedShape, ShapeGrid
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.datasheet import analysed_from, settle, tip_sweep
from tsmd.datasheet_shape import measure_loaded_shape
from tsmd.errors import TsmdError
from tsmd.replay import run_trajectory

GRID_CYCLES = 2.0
"""Analysed cycles per held angle after the conditioning cycle (both sides need a whole pass)."""


def held_templates(plant_factory: Callable[[], Plant], knob: int, held_deg: float,
                   omega: float, seed: int, config: TsmdConfig
                   ) -> tuple[LoadedShape | None, LoadedShape | None]:
    """One knob's templates (positive, negative side) with the other knob held at ``held_deg``."""
    period_s = config.loop.period_s
    t, q, skip = settle(*tip_sweep(knob, held_deg, period_s, GRID_CYCLES), period_s)
    rec = run_trajectory(t, q, config=config, profile=None, method="none", seed=seed,
                         plant=plant_factory())
    a = analysed_from(skip, period_s)
    k = knob + 1
    pos = np.asarray(rec[f"pos{k}"][a:], dtype=float)
    tip = np.asarray(rec[f"tip{k}"][a:], dtype=float)
    cur = identify_sweep(np.asarray(rec["t"][a:], dtype=float),
                         np.asarray(rec[f"cmd{k}"][a:], dtype=float), pos,
                         np.asarray(rec[f"cur{k}"][a:], dtype=float))
    return (measure_loaded_shape(pos, tip, round(cur.estimate("dead_zone_pos_deg"), 2), omega, 1),
            measure_loaded_shape(pos, tip, round(cur.estimate("dead_zone_neg_deg"), 2), omega,
                                 -1))


def measure_shape_grids(plant_factory: Callable[[], Plant], omegas: Sequence[float],
                        seed: int = 2000, config: TsmdConfig | None = None,
                        grid_deg: Sequence[float] = CALIBRATION_GRID_DEG
                        ) -> list[tuple[ShapeGrid, ShapeGrid]]:
    """Each knob's templates over the other knob's angle (``omegas``: the sheet's, as printed).
    An angle where a side shows no whole loaded pass is left out; fewer than two left is an
    error (one line)."""
    cfg = config if config is not None else default_sim_config()
    out = []
    for knob, omega in enumerate(omegas):
        angles, pos, neg = [], [], []
        for held in grid_deg:
            sp, sn = held_templates(plant_factory, knob, float(held), float(omega), seed, cfg)
            if sp is not None and sn is not None:
                angles.append(float(held))
                pos.append(sp)
                neg.append(sn)
        if len(angles) < 2:
            raise TsmdError(f"loaded-shape grid: knob {knob + 1} shows a whole loaded pass on "
                            f"both sides at {len(angles)} of {len(grid_deg)} other-knob angles")
        out.append((ShapeGrid(tuple(angles), tuple(pos)), ShapeGrid(tuple(angles), tuple(neg))))
    return out
