"""Tracked sweeps of a known tension play: what a data-sheet stage sees on its unit."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from tsmd.compensation.model_parts import model_parts
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.datasheet_level_grid import TrackedSweep


def tracked_sweeps(truth: TensionPlayParams, angles: Sequence[float], repeats: int = 1
                   ) -> list[tuple[float, TrackedSweep]]:
    """``repeats`` +-90 deg sweeps (0.04 Hz, 50 Hz) per other-knob angle, the other knob held
    there, the tip as ``truth`` says; each with its angle."""
    t = np.arange(0.0, 50.0, 0.02)
    x = -90.0 * np.cos(2 * np.pi * 0.04 * t)
    out = []
    for other in angles:
        held = np.full_like(x, other)
        tip, _ = model_parts(x, held, truth, 0.0)
        out += [(other, TrackedSweep(x, held, tip))] * repeats
    return out
