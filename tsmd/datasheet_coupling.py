"""The product's coupling of the tip planes, measured on the data sheet's unit (tracked tip).

A shaft that winds up in torsion turns the two bending planes into each other: with the other
knob held bent, a knob's tip stands off its plateau by a share of the other plane's tip angle
(twistshaft unit 0: 6.9 deg with the other tip at 78 deg, linear in that tip to 0.2 deg; the
other plants: none). The current cannot show it (the knob's tendons carry no load in the dead
zone), so it is a product constant: each knob swept +-90 deg at 0.04 Hz with the other knob held
at -90 and +90 deg; the gain is the change of the plateau's middle (the tip in the middle of the
dead zone, median over both directions) over the change of the other tip.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from simrig.plant import Plant
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.datasheet import SWEEP_HZ, analysed_from, settle, tip_sweep
from tsmd.errors import TsmdError
from tsmd.replay import run_trajectory

HELD_OTHER_DEG = 90.0
"""The other knob is held at -this and +this (the knob range's ends: the largest lever)."""
COUPLING_CYCLES = 1.0
"""Analysed cycles per held angle, after the conditioning cycle."""
PLATEAU_SHARE = 0.4
"""The tip is read where the knob is within this share of the nearer dead-zone edge of 0."""


def plateau_middle_deg(knob_deg: np.ndarray, tip_deg: np.ndarray, edge_deg: float) -> float:
    """The middle of the play's plateau: the median tip moving up and moving down while the
    knob is well inside the dead zone (``edge_deg``: the nearer edge's distance from 0)."""
    v = np.gradient(knob_deg)
    inside = np.abs(knob_deg) < PLATEAU_SHARE * edge_deg
    up, down = tip_deg[inside & (v > 0)], tip_deg[inside & (v < 0)]
    if up.size < 10 or down.size < 10:
        raise TsmdError("coupling: the sweep does not cross the dead zone both ways")
    return 0.5 * (float(np.median(up)) + float(np.median(down)))


def measure_other_tip_gains(plant_factory: Callable[[], Plant], edges_deg: tuple[float, float],
                            seed: int = 2000, config: TsmdConfig | None = None
                            ) -> tuple[float, float]:
    """Each knob's tip degrees per tip degree of the other plane (``edges_deg``: each knob's
    nearer dead-zone edge from 0, e.g. the sheet's reference edges)."""
    cfg = config if config is not None else default_sim_config()
    period_s = cfg.loop.period_s
    gains = []
    for knob in (0, 1):
        middles, others = [], []
        for held in (-HELD_OTHER_DEG, HELD_OTHER_DEG):
            t, q, skip = settle(*tip_sweep(knob, held, period_s, COUPLING_CYCLES), period_s)
            rec = run_trajectory(t, q, config=cfg, profile=None, method="none", seed=seed,
                                 plant=plant_factory())
            a = analysed_from(skip, period_s)
            n = a + round(COUPLING_CYCLES / SWEEP_HZ / period_s)
            k, o = knob + 1, 2 - knob
            middles.append(plateau_middle_deg(rec[f"pos{k}"][a:n], rec[f"tip{k}"][a:n],
                                              edges_deg[knob]))
            others.append(float(np.median(rec[f"tip{o}"][a:n])))
        span = others[1] - others[0]
        if not abs(span) > 1.0:
            raise TsmdError(f"coupling: the other knob's tip did not move ({span:.2f} deg)")
        gains.append((middles[1] - middles[0]) / span)
    return gains[0], gains[1]
