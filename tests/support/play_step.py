"""A swept knob whose flat current steps where the handle's play closes (session 24)."""

from __future__ import annotations

import math

import numpy as np

PERIOD_S = 0.004
SWING_DEG = 3.0
PLAY_DEG = 13.0
EDGE_DEG = 30.0


def sweep(step_A: float, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Two and a half +-90 deg cycles: after each reversal the direction-signed current swings
    to its release level over SWING_DEG, steps by ``step_A`` PLAY_DEG after the reversal (the
    play closing), and rises on the loaded ramp past +-EDGE_DEG."""
    t = np.arange(0.0, 2.5 / 0.06, PERIOD_S)
    q = 90.0 * np.sin(2 * math.pi * 0.06 * t - math.pi / 2)
    direction = np.where(np.gradient(q, PERIOD_S) >= 0, 1.0, -1.0)
    turns = np.flatnonzero(np.diff(direction) != 0) + 1
    last = np.zeros_like(q)
    starts = np.concatenate([[0], turns])
    for a, b in zip(starts, np.concatenate([turns, [q.size]]), strict=True):
        last[a:b] = q[a]
    travel = np.abs(q - last)
    signed = (-0.05 + 0.08 * np.minimum(travel / SWING_DEG, 1.0) + step_A * (travel >= PLAY_DEG)
              + 0.004 * np.maximum(direction * q - EDGE_DEG, 0.0))
    current = direction * signed + np.random.default_rng(seed).normal(0.0, 0.002, t.size)
    return t, q, current
