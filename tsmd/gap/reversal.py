"""The protocol's slow reversals of one knob, read for the compliance figure.

Per reversal: the tip's return and the motor current against the knob travel after it, the
current before it, the knob angle where it turned and the configuration. Only reversals with
both knobs at the same angle and at most :data:`MAX_SPEED_DEG_S` (the warm-up, the rate
test's slow loops, the dwells); the first of each recording starts from a straight catheter.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.data import GapSeries

FloatArray = NDArray[np.float64]

MAX_SPEED_DEG_S = 45.0
"""Reversals at most this fast are read (the protocol's 20 and 40 deg/s): a fast reversal
passes the lost motion in a few samples and adds the current's viscous part to its swing."""
TRAVEL_GRID_DEG = np.arange(0.0, 40.0, 0.05)
"""Knob travel after a reversal on which the repeats' curves are averaged (finer than the
knob's sample step: a return within one sample still reads between samples)."""
REFERENCE_TRAVEL_DEG = 1.0
"""The tip before its return: its mean over this much travel after the reversal."""
PRE_WINDOW_S = 0.2
"""The current at a reversal: its mean over this long before it."""
TOGETHER_DEG = 2.0
"""Only reversals with the other knob at the same angle (the protocol moves both knobs
together in its warm-up, rate loops and dwells): the other knob's angle changes the load, and
coupling is another effect."""


@dataclass(frozen=True)
class Reversals:
    """Per slow reversal of one knob: the tip's return and the current against the knob travel
    after it (on :data:`TRAVEL_GRID_DEG`, NaN beyond the motion), the current before it, the
    knob angle of the reversal and the configuration."""

    tip_return_deg: FloatArray
    current_A: FloatArray
    before_A: FloatArray
    at_deg: FloatArray
    config: NDArray[np.int64]


def _reversal_pairs(x: FloatArray) -> list[tuple[int, int]]:
    """(last row moving the old way, first row moving the new way) at each reversal."""
    s = np.sign(np.round(np.diff(x), 9))
    moving = np.flatnonzero(s != 0)
    return [(int(a) + 1, int(b) + 1) for a, b in itertools.pairwise(moving)
            if s[a] != s[b]]


def _after(x: FloatArray, a: int, b: int) -> tuple[FloatArray, int]:
    """Knob travel from the reversal at row ``a`` over the motion that leaves it, and its end."""
    direction = np.sign(x[b] - x[a])
    steps = np.sign(np.round(np.diff(x[b:]), 9))
    against = np.flatnonzero(steps == -direction)
    end = b + 1 + (int(against[0]) if against.size else len(steps))
    return np.abs(x[a:end] - x[a]), end


def reversals(series: Sequence[GapSeries], knob: int) -> Reversals:
    """Every slow reversal of ``knob`` in the protocol recordings with the other knob at the
    same angle (the first of each recording left out: it starts from the straight catheter)."""
    configs = sorted({s.config for s in series})
    ret, cur_on, before, at, cfg = [], [], [], [], []
    for s in series:
        if s.segment is None:
            continue
        x, tip, cur = s.knob_deg[:, knob], s.tip_deg[:, knob], s.current_A[:, knob]
        dt = float(np.median(np.diff(s.t_s)))
        pre = max(round(PRE_WINDOW_S / dt), 1)
        for a, b in _reversal_pairs(x)[1:]:
            speed = max(abs(x[a] - x[a - 1]), abs(x[b] - x[a])) / dt
            if (a < pre or speed > MAX_SPEED_DEG_S
                    or abs(s.knob_deg[a, 1 - knob] - x[a]) > TOGETHER_DEG):
                continue
            travel, end = _after(x, a, b)
            direction = np.sign(x[b] - x[a])
            start = float(np.mean(tip[a:end][travel <= REFERENCE_TRAVEL_DEG]))
            ret.append(np.interp(TRAVEL_GRID_DEG, travel, direction * (tip[a:end] - start),
                                 right=np.nan))
            cur_on.append(np.interp(TRAVEL_GRID_DEG, travel, cur[a:end], right=np.nan))
            before.append(float(np.mean(cur[a - pre:a + 1])))
            at.append(float(x[a]))
            cfg.append(configs.index(s.config))
    grid = len(TRAVEL_GRID_DEG)
    return Reversals(np.array(ret, dtype=float).reshape(-1, grid),
                     np.array(cur_on, dtype=float).reshape(-1, grid),
                     np.array(before, dtype=float), np.array(at, dtype=float),
                     np.array(cfg, dtype=np.int64))
