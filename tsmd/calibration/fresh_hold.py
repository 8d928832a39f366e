"""A fresh catheter's first-release hold, from the current of the calibration's first sweep.

The first sweep starts on a catheter that has never been loaded (straight, both tendons at
their initial tension) and visits +A before coming down to -A: on that first way down the
other tendon takes over later than on every later release (the capstan plant: ~8-17 knob deg
on the family's units). The current shows it as the negative edge of that first falling
half-cycle lying above the edge of the later ones; the difference is the profile's
``fresh_hold_deg`` (:func:`tsmd.compensation.fresh_play.fresh_branches`). Only the knob
swept first is fresh when its sweep starts: the other knob has been moved (loaded) by then.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from tsmd.calibration.identify import analyse_half_cycle, split_half_cycles
from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.signal import Conditioned

MIN_HOLD_DEG = 2.0
"""A smaller hold is not a fresh release: the edges of one sweep repeat within 0.25-0.5 deg and
the first move runs at another speed than the sweep. Without a fresh release seen, the first
loading's edge delay is not taken either: on the capstan plant both come from the fresh
tendons and come together; a plant whose first sweep shows no hold (the lumped plant: 0-0.5
deg, with edge delays of 0.9-2.1 deg) starts like a conditioned one."""


def fresh_hold_deg(data: Conditioned, options: IdentifyOptions | None = None) -> float:
    """The first release's edge minus the same side's median edge after it (0 if none)."""
    return fresh_differences(data, options)[0]


def fresh_differences(data: Conditioned, options: IdentifyOptions | None = None
                      ) -> tuple[float, float]:
    """(hold, edge delay) in knob degrees from a first sweep that starts fresh: the hold as in
    :func:`fresh_hold_deg`; the edge delay: how much later the first loading's edge lies than
    the same side's median edge on the later loadings (0 where not seen)."""
    opts = options or IdentifyOptions()
    halves = split_half_cycles(data.cmd_deg, opts.min_reversal_deg)
    if len(halves) < 3:
        return 0.0, 0.0
    first_dir = halves[0][0]
    edges = [(d, analyse_half_cycle(data, d, a, b, after, opts).edge_deg)
             for d, a, b, after in halves]
    out = []
    for side in (-first_dir, first_dir):
        mine = [e for d, e in edges if d == side]  # that direction's edges, first one first
        later = [e for e in mine[1:] if math.isfinite(e)]
        if not mine or not math.isfinite(mine[0]) or not later:
            out.append(0.0)
            continue
        # how much later the first edge of that direction lies (for the other side, the
        # first release: the other tendon takes over later)
        out.append(first_dir * (mine[0] - float(np.median(later))))
    if out[0] < MIN_HOLD_DEG:
        return 0.0, 0.0
    return min(out[0], 90.0), min(max(out[1], -45.0), 45.0)


def with_fresh_hold(params: Sequence[Any], points: Sequence[Any]) -> tuple[Any, ...]:
    """``params`` (per knob) with the first sweep's knob's ``fresh_hold_deg`` and
    ``fresh_edge_delay_deg``."""
    if not points:
        return tuple(params)
    first = points[0]
    hold, delay = fresh_differences(first.result.data)
    return tuple(replace(p, fresh_hold_deg=hold, fresh_edge_delay_deg=delay) if k == first.knob
                 else p for k, p in enumerate(params))
