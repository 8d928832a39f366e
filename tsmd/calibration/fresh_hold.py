"""A fresh catheter's first-release hold, from the current of the calibration's first sweep.

The first sweep starts on a catheter that has never been loaded (straight, both tendons at
their initial tension) and visits +A before coming down to -A: on that first way down the
other tendon takes over later than on every later release (the capstan plant: ~8-17 knob deg
on the family's units). The current shows it as the negative edge of that first falling
half-cycle lying above the edge of the later ones; the difference is the profile's
``fresh_hold_deg`` (:func:`tsmd.compensation.tension_play.fresh_branches`). Only the knob
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


def fresh_hold_deg(data: Conditioned, options: IdentifyOptions | None = None) -> float:
    """The first release's edge minus the same side's median edge after it (0 if none)."""
    opts = options or IdentifyOptions()
    halves = split_half_cycles(data.cmd_deg, opts.min_reversal_deg)
    if len(halves) < 3:
        return 0.0
    first_dir = halves[0][0]
    edges = [analyse_half_cycle(data, d, a, b, after, opts).edge_deg
             for d, a, b, after in halves[1:] if d == -first_dir]
    later = [e for e in edges[1:] if math.isfinite(e)]
    if not edges or not math.isfinite(edges[0]) or not later:
        return 0.0
    # after a positive first loading the negative edge lies higher (mirrored after a negative)
    hold = first_dir * (edges[0] - float(np.median(later)))
    return min(max(hold, 0.0), 90.0)


def with_fresh_hold(params: Sequence[Any], points: Sequence[Any]) -> tuple[Any, ...]:
    """``params`` (per knob) with the first sweep's knob's ``fresh_hold_deg``."""
    if not points:
        return tuple(params)
    first = points[0]
    hold = fresh_hold_deg(first.result.data)
    return tuple(replace(p, fresh_hold_deg=hold) if k == first.knob else p
                 for k, p in enumerate(params))
