"""The loaded ramp one stroke shows: referred to the profile's edge, its window placed.

Apart from :class:`tsmd.online.worker.OnlineWorker` because it only reads the stroke, the
profile's knob and the edge's tracker; the worker decides what the ramp changes.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from tsmd.online.estimator import EdgeTracker
from tsmd.online.features import (
    LoadedRamp,
    RampOptions,
    Rejected,
    Stroke,
    find_knee_deg,
    loaded_ramp,
    relocated_edge_deg,
)


def referred_stroke(stroke: Stroke, base_knob: Any) -> tuple[Stroke, float]:
    """The stroke with the profile's own edge motion taken out, and that edge.

    The profile says how the edge moves with the other knob's angle; over one stroke the
    other knob may move far. Each sample's angle is moved by the profile edge's change
    from the stroke's middle, so the ramp's foot stays put unless the catheter changed.
    """
    f = base_knob.field
    column = 0 if stroke.direction > 0 else 1
    grid = np.asarray(f.grid_deg, dtype=float)
    values = np.asarray(f.values, dtype=float)[:, column]
    mid = float(np.median(stroke.other_deg))
    edge = float(f.at(mid)[column])
    moved = np.interp(stroke.other_deg, grid, values) - float(np.interp(mid, grid, values))
    return replace(stroke, cmd_deg=stroke.cmd_deg - moved, pos_deg=stroke.pos_deg - moved,
                   other_deg=np.full_like(stroke.other_deg, mid)), edge


def stroke_ramp(stroke: Stroke, edge_deg: float, tracker: EdgeTracker,
                options: RampOptions) -> LoadedRamp | Rejected:
    """The loaded ramp of a (referred) stroke whose profile edge is ``edge_deg``: the window
    starts past the stroke's knee in knee mode, else where the reference ramp places the edge
    (:func:`relocated_edge_deg`), and past the knee when that relocation gives an implausible
    slope."""
    expected = edge_deg + stroke.direction * tracker.applied_deg
    knee = find_knee_deg(stroke, expected, options)
    if math.isfinite(knee[0]) and tracker.knee_mode:
        expected = knee[0]  # the window starts past the engagement this stroke shows
    elif tracker.level_A is not None and tracker.slope_ref_A_per_deg is not None:
        expected = relocated_edge_deg(stroke, expected, tracker.level_A,
                                      tracker.slope_ref_A_per_deg, options)
    ramp = loaded_ramp(stroke, expected, options, knee)
    if math.isfinite(knee[0]) and expected != knee[0] and not tracker.plausible(ramp):
        # The reference ramp's relocation assumes an unchanged ramp: after a bend it can
        # put the window inside the dead zone (a flat "ramp"); past the knee it is not.
        at_knee = loaded_ramp(stroke, knee[0], options, knee)
        ramp = at_knee if isinstance(at_knee, LoadedRamp) else ramp
    return ramp


__all__ = ["referred_stroke", "stroke_ramp"]
