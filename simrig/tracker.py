"""Simulated electromagnetic tracker on the catheter tip: ground truth for evaluation only."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray


class EmTracker:
    """Adds the tracker's Gaussian angle noise (degrees, 1 sigma) to the true tip angle.

    Deterministic for a given ``seed``; the default 0.1 deg is of the order of a 6-DOF EM
    sensor's orientation accuracy. The noise is drawn in blocks (one generator call per
    ``block`` values instead of one per tick): nothing else draws from this generator, so the
    sequence is the same as drawing per call.
    """

    block = 4096

    def __init__(self, noise_deg: float = 0.1, seed: int = 0) -> None:
        if not math.isfinite(noise_deg) or noise_deg < 0.0:
            raise ValueError(f"noise_deg must be finite and >= 0, got {noise_deg!r}")
        self.noise_deg = float(noise_deg)
        self.seed = seed
        self.reset()

    def reset(self) -> None:
        """Restart the noise sequence."""
        self._rng = np.random.default_rng(self.seed)
        self._noise: list[float] = []
        self._next = 0

    def _standard_normal(self, n: int) -> list[float]:
        """The next ``n`` values of the generator's standard normal stream."""
        end = self._next + n
        if end > len(self._noise):
            rest = self._noise[self._next:]
            self._noise = rest + self._rng.standard_normal(max(self.block, n)).tolist()
            self._next, end = 0, n
        out = self._noise[self._next:end]
        self._next = end
        return out

    def measure(self, tip_deg: ArrayLike) -> NDArray[np.float64]:
        """Tracked tip angles (same shape as ``tip_deg``)."""
        true = np.asarray(tip_deg, dtype=np.float64)
        if self.noise_deg == 0.0:
            return true.copy()
        noise = np.array(self._standard_normal(true.size), dtype=np.float64)
        return true + self.noise_deg * noise.reshape(true.shape)

    def measure_pair(self, tip0_deg: float, tip1_deg: float) -> tuple[float, float]:
        """:meth:`measure` of two angles as floats (same draws, same arithmetic, no arrays)."""
        s = self.noise_deg
        if s == 0.0:
            return tip0_deg, tip1_deg
        i = self._next
        noise = self._noise
        if i + 2 > len(noise):
            z0, z1 = self._standard_normal(2)
        else:
            z0, z1 = noise[i], noise[i + 1]
            self._next = i + 2
        return tip0_deg + s * z0, tip1_deg + s * z1
