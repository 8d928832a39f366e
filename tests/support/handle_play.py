"""A synthetic release after a reversal through a handle's play, shared by the play-engage and
play-creep tests: the current a drum shows when its play closes ``play_end_deg`` after the
reversal (knob deg), with the sheet's reading offset that announces such a play."""

from __future__ import annotations

import numpy as np

from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import HalfCycle, SweepResult
from tsmd.profile.reading_offset import OffsetGrid, ReadingOffset

LEVEL_A = 0.026
"""Friction level the current rests at while the knob crosses the play (A)."""
PULL_A = 0.011
"""Step of the released rope's pull where the play closes (A)."""
NOISE_A = 0.001
LINE_END_DEG = 3.0
"""Where the line rule ends the unloading (knob deg after the reversal)."""
OTHER_DEG = (-90.0, 0.0, 90.0)


def release_y(travel_deg: np.ndarray, play_end_deg: float | None) -> np.ndarray:
    """Direction-signed current after a reversal: the tension unloads over the line rule's
    3 deg, the current rests at the level over the play, then the released rope's pull lowers
    it by PULL_A, fading over 50 deg (None: no step, the level to the end)."""
    y = np.full_like(travel_deg, LEVEL_A)
    unload = travel_deg < LINE_END_DEG
    y[unload] = -0.08 + (LEVEL_A + 0.08) * travel_deg[unload] / LINE_END_DEG
    if play_end_deg is not None:
        s = travel_deg - play_end_deg
        pulled = (s >= 0.0) & (s < 50.0)
        y[pulled] = LEVEL_A - PULL_A * (1.0 - s[pulled] / 50.0)
    return y


def falling_sweep(play_end_deg: float | None, seed: int = 0) -> SweepResult:
    """One half-cycle down from +90 deg (the + side's backlash) with the line rule's B."""
    pos = np.linspace(90.0, -60.0, 1501)
    travel = 90.0 - pos
    y = release_y(travel, play_end_deg) + np.random.default_rng(seed).normal(0.0, NOISE_A / 4,
                                                                            pos.size)
    current = -y  # direction -1
    t = np.arange(pos.size) * 0.02
    data = Conditioned(t, pos, pos, current, current, 50.0, NOISE_A, NOISE_A, ())
    half = HalfCycle(direction=-1, start=0, stop=pos.size, after_reversal=True,
                     backlash_deg=LINE_END_DEG)
    return SweepResult(data, (half,), {"backlash_pos_deg": (LINE_END_DEG,)})


def reversing_sweep(pos_end_deg: float, neg_end_deg: float, seed: int = 0) -> SweepResult:
    """Down from +90 deg and back up from -60 deg: both sides' backlashes, each with the line
    rule's B, the play closing ``pos_end_deg`` / ``neg_end_deg`` after its reversal."""
    down, up = np.linspace(90.0, -60.0, 1501), np.linspace(-60.0, 90.0, 1501)[1:]
    rng = np.random.default_rng(seed)
    y_down = release_y(90.0 - down, pos_end_deg) + rng.normal(0.0, NOISE_A / 4, down.size)
    y_up = release_y(up + 60.0, neg_end_deg) + rng.normal(0.0, NOISE_A / 4, up.size)
    pos = np.concatenate([down, up])
    current = np.concatenate([-y_down, y_up])
    t = np.arange(pos.size) * 0.02
    data = Conditioned(t, pos, pos, current, current, 50.0, NOISE_A, NOISE_A, ())
    halves = (HalfCycle(direction=-1, start=0, stop=down.size, after_reversal=True,
                        backlash_deg=LINE_END_DEG),
              HalfCycle(direction=1, start=down.size - 1, stop=pos.size, after_reversal=True,
                        backlash_deg=LINE_END_DEG))
    return SweepResult(data, halves, {"backlash_pos_deg": (LINE_END_DEG,),
                                      "backlash_neg_deg": (LINE_END_DEG,)})


def play_offset(play_deg: float,
                names: tuple[str, ...] = ("backlash_pos_deg",)) -> ReadingOffset:
    """The sheet's reading offset of ``names`` (B_pos): ``play_deg`` at every other-knob
    angle."""
    grid = OffsetGrid((play_deg,) * 3, (0.5,) * 3, (4, 4, 4))
    return ReadingOffset(OTHER_DEG, tuple((name, grid) for name in names))
