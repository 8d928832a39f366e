"""The tension-play model run over a knob trajectory, labelled by the part of its play.

At every sample the model is on one of four parts: ``loaded`` (on a branch, beyond the plateau
in the direction of motion), ``release`` (on a branch, on the near side of the plateau),
``plateau`` (a branch's flat: the dead zone) or ``backlash`` (the output held after a
reversal). The tracking bench splits ours' error by it (:mod:`tsmd.bench.error_split`) and the
datasheet's level grid compares the tip with the model per part
(:mod:`tsmd.datasheet_level_grid`); a pure function, no I/O.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from tsmd.compensation.ours_table import ours_knobs
from tsmd.compensation.tension_play import PlayState, model_step
from tsmd.compensation.tension_play_params import TensionPlayParams

FloatArray = NDArray[np.float64]
PARTS: tuple[str, ...] = ("loaded", "release", "plateau", "backlash")
FLAT_TOLERANCE_DEG = 0.05
"""A model output this close to the branch's plateau height is on the flat (the flats carry a
1e-6 tilt that keeps the branches invertible)."""


def model_parts(x_deg: FloatArray, other_deg: FloatArray, params: TensionPlayParams,
                start_deg: float) -> tuple[FloatArray, list[str]]:
    """The model's output for the knob angles ``x_deg`` (the other knob at ``other_deg``),
    started at rest at ``start_deg``, and the part of the play of each sample."""
    knob = ours_knobs([params, params])[0]
    state = PlayState(float(x_deg[0]), float(start_deg), 1, float(start_deg))
    y = np.empty(len(x_deg))
    parts: list[str] = []
    for i, (x, other) in enumerate(zip(x_deg, other_deg, strict=True)):
        b = knob.at(float(other))
        state = model_step(state, float(x), b)
        y[i] = state.y_deg
        branch = b.rising(float(x)) if state.direction > 0 else b.falling(float(x))
        flat = params.height_pos_deg if state.direction > 0 else params.height_neg_deg
        on_line = state.line_slope > 0.0 and state.y_deg != state.held_deg  # a reversal's line
        if abs(branch - state.y_deg) > 1e-9 and not on_line:
            parts.append("backlash")
        elif abs(state.y_deg - flat) <= FLAT_TOLERANCE_DEG:
            parts.append("plateau")
        elif state.direction * (state.y_deg - flat) > 0.0:
            parts.append("loaded")
        else:
            parts.append("release")
    return y, parts
