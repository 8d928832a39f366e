"""Synthetic per-tick rows for the online estimator: a closed-form motor current, not a plant.

Each knob follows a sine; its direction-signed current is the handle's friction inside the dead
zone, and beyond an edge a jump (the tendon engaging) plus a linear loaded ramp whose foot is the
edge. ``edges(t, knob, other_deg)`` gives the true edges, so a test can move them at a known time
(and make them follow the other knob's angle as the calibrated profile says they do).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from tsmd.loop import ROW_COLUMNS

Edges = Callable[[float, int, float], tuple[float, float]]
"""(time, knob, other knob's angle) -> that knob's true (D_pos, D_neg)."""

FRICTION_A = 0.02
ENGAGE_A = 0.03
SLOPE_A_PER_DEG = 0.003


def knob_current(pos: float, velocity: float, d_pos: float, d_neg: float,
                 friction_x: float = 1.0) -> float:
    """Motor current of one knob at ``pos`` moving at ``velocity`` (deg/s); ``friction_x``
    scales the engagement's step and the loaded ramp (a sheath bend's friction)."""
    direction = 1.0 if velocity >= 0 else -1.0
    current = FRICTION_A * direction
    if direction > 0 and pos > d_pos:
        current += friction_x * (ENGAGE_A + SLOPE_A_PER_DEG * (pos - d_pos))
    elif direction < 0 and pos < d_neg:
        current -= friction_x * (ENGAGE_A + SLOPE_A_PER_DEG * (d_neg - pos))
    return current


def rows(duration_s: float, edges: Edges, *, period_s: float = 0.004, noise_A: float = 0.003,
         spike_rate: float = 0.0, stall: tuple[int, float, float] | None = None,
         friction: tuple[float, float] = (math.inf, 1.0),
         seed: int = 0) -> list[tuple[float, ...]]:
    """Rows in ``ROW_COLUMNS`` layout. ``stall = (knob, t0, t1)``: between t0 and t1 that
    knob's position stays where it was while its command goes on (a stalled motor).
    ``friction = (t0, x)``: from t0 on, every tendon's current ramp is ``x`` times steeper."""
    rng = np.random.default_rng(seed)
    out = []
    n = int(duration_s / period_s)
    held: float | None = None
    for i in range(n):
        t = i * period_s
        cmd = (60.0 * math.sin(2 * math.pi * 0.05 * t), 55.0 * math.sin(2 * math.pi * 0.043 * t
                                                                         + 1.0))
        vel = (60.0 * 2 * math.pi * 0.05 * math.cos(2 * math.pi * 0.05 * t),
               55.0 * 2 * math.pi * 0.043 * math.cos(2 * math.pi * 0.043 * t + 1.0))
        pos = list(cmd)
        if stall is not None and stall[1] <= t < stall[2]:
            if held is None:
                held = pos[stall[0]]
            pos[stall[0]] = held
            vel = tuple(0.0 if k == stall[0] else v for k, v in enumerate(vel))  # type: ignore
        else:
            held = None
        cur = []
        for k in (0, 1):
            d_pos, d_neg = edges(t, k, pos[1 - k])
            fx = friction[1] if t >= friction[0] else 1.0
            c = knob_current(pos[k], vel[k], d_pos, d_neg, fx) + noise_A * rng.standard_normal()
            if spike_rate and rng.random() < spike_rate:
                c += 0.3 * (1 if rng.random() < 0.5 else -1)
            if stall is not None and k == stall[0] and stall[1] <= t < stall[2]:
                c = 0.8  # the motor pushes against the block at its current limit
            cur.append(c)
        values = {"t": t, "q1": cmd[0], "q2": cmd[1], "cmd1": cmd[0], "cmd2": cmd[1],
                  "pos1": pos[0], "pos2": pos[1], "cur1": cur[0], "cur2": cur[1],
                  "tip1": math.nan, "tip2": math.nan}
        out.append(tuple(float(values[c]) for c in ROW_COLUMNS))
    return out


def profile_edges(knobs: Sequence[Any], shift_deg: float = 0.0, at_s: float = math.inf,
                  other_below: tuple[float, float] = (-math.inf, 0.0)) -> Edges:
    """The edges a compensator's knobs have at the other knob's angle (the catheter is as
    calibrated), moved outward by ``shift_deg`` from ``at_s`` on; ``other_below = (angle,
    deg)``: with the other knob below that angle, both edges sit ``deg`` further out (a
    coupling the profile's grid does not hold)."""
    def edges(t: float, knob: int, other_deg: float) -> tuple[float, float]:
        values = knobs[knob].field.at(other_deg)
        s = shift_deg if t >= at_s else 0.0
        s += other_below[1] if other_deg < other_below[0] else 0.0
        return float(values[0]) + s, float(values[1]) - s
    return edges
