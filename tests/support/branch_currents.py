"""Synthetic motor current around a dead-zone edge, built from tendon mechanics (not from the
estimator's branch model): a tendon with a slack toe, and a tendon that stretches steeply
while the tip is held before the loaded ramp."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def knob_grid(lo_deg: float = 0.0, hi_deg: float = 40.0, step_deg: float = 0.25) -> FloatArray:
    return np.arange(lo_deg, hi_deg, step_deg)


def toe_current(x_deg: FloatArray, engage_deg: float, toe_deg: float, level_A: float = 0.03,
                A_per_deg: float = 0.002) -> FloatArray:
    """Tendon tension of a quadratic toe that turns linear after ``toe_deg`` of stretch (the
    lumped plant's free segment), as current: its linear part, extended back, meets the level
    at ``engage_deg + toe_deg / 2``."""
    e = np.maximum(x_deg - engage_deg, 0.0)
    tension = np.where(e < toe_deg, 0.5 * e * e / toe_deg, e - 0.5 * toe_deg)
    return level_A + A_per_deg * tension


def steep_then_loaded_current(x_deg: FloatArray, engage_deg: float, release_deg: float,
                              level_A: float = 0.03, steep_A_per_deg: float = 0.008,
                              loaded_A_per_deg: float = 0.002) -> FloatArray:
    """The tendon stretching against a held tip (steep), until the tip gives at
    ``release_deg`` and the current follows the loaded ramp; smoothed over 1 deg like a
    filtered sensor."""
    y = level_A + steep_A_per_deg * np.clip(x_deg - engage_deg, 0.0, release_deg - engage_deg)
    y += loaded_A_per_deg * np.maximum(x_deg - release_deg, 0.0)
    kernel = np.ones(5) / 5.0
    return np.convolve(np.pad(y, 2, mode="edge"), kernel, mode="valid")


def noisy(y: FloatArray, sigma_A: float, seed: int, spikes: int = 0,
          spike_A: float = 0.05) -> FloatArray:
    """White noise and isolated spikes (a sensor glitch) on a current."""
    rng = np.random.default_rng(seed)
    out = y + rng.normal(0.0, sigma_A, y.size)
    if spikes:
        where = rng.choice(y.size, spikes, replace=False)
        out[where] += spike_A * rng.choice([-1.0, 1.0], spikes)
    return out


def wall_current(x_deg: FloatArray, engage_deg: float, level_A: float = 0.03,
                 first_A_per_deg: float = 0.007, loaded_A_per_deg: float = 0.0035,
                 bend_deg: float = 8.0) -> FloatArray:
    """The tip pressed into a soft wall that stiffens and saturates: from ``engage_deg`` (where
    the tip starts to move) the current rises at ``first_A_per_deg`` and its slope falls
    smoothly (exponentially over ``bend_deg``) to ``loaded_A_per_deg``: no corner."""
    e = np.maximum(x_deg - engage_deg, 0.0)
    extra = (first_A_per_deg - loaded_A_per_deg) * bend_deg * (1.0 - np.exp(-e / bend_deg))
    return level_A + loaded_A_per_deg * e + extra
