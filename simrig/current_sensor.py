"""Motor-current sensing as a drive reports it: lag, gain and offset errors, noise and spikes.

The simulated drive turns the true motor current into the measured one with this class, so the
calibration sees the same imperfections as on the robot (the real TEE data shows spikes of
+-50 mA and more on top of +-150 mA of load current).
"""

from __future__ import annotations

import math

import numpy as np


class CurrentSensor:
    """First-order lag, gain and offset error, Gaussian noise and occasional spikes.

    Deterministic for a given ``seed``. ``measure`` is called once per control period. The
    parameters are fixed at construction (the per-period factors are kept per ``dt_s``).
    """

    def __init__(
        self,
        lag_s: float = 0.0,
        offset_A: float = 0.0,
        noise_A: float = 0.0,
        spike_rate_hz: float = 0.0,
        seed: int = 0,
        *,
        gain: float = 1.0,
        spike_A: float = 0.05,
    ) -> None:
        for name, value in (
            ("lag_s", lag_s),
            ("noise_A", noise_A),
            ("spike_rate_hz", spike_rate_hz),
            ("spike_A", spike_A),
        ):
            if not math.isfinite(value) or value < 0.0:
                raise ValueError(f"{name} must be finite and >= 0, got {value!r}")
        if not math.isfinite(offset_A):
            raise ValueError(f"offset_A must be finite, got {offset_A!r}")
        if not math.isfinite(gain) or gain <= 0.0:
            raise ValueError(f"gain must be finite and > 0, got {gain!r}")
        self.lag_s = float(lag_s)
        self.offset_A = float(offset_A)
        self.noise_A = float(noise_A)
        self.spike_rate_hz = float(spike_rate_hz)
        self.gain = float(gain)
        self.spike_A = float(spike_A)
        self.seed = seed
        self.reset()

    def reset(self) -> None:
        """Forget the filter state and restart the random sequence."""
        self._rng = np.random.default_rng(self.seed)
        self._normal = self._rng.standard_normal
        self._uniform = self._rng.random
        self._filtered_A: float | None = None
        self._dt_s = math.nan
        self._lag_gain = 1.0
        self._spike_p = 0.0

    def _per_period(self, dt_s: float) -> None:
        """The filter gain and the spike probability of a period of ``dt_s`` (computed once
        per period length, by the same expressions)."""
        self._dt_s = dt_s
        if self.lag_s != 0.0:
            self._lag_gain = 1.0 - math.exp(-dt_s / self.lag_s)
        self._spike_p = -math.expm1(-self.spike_rate_hz * dt_s)

    def measure(self, dt_s: float, true_current_A: float) -> float:
        """The reading after ``dt_s`` more seconds of ``true_current_A`` (amperes)."""
        if dt_s != self._dt_s:
            if not dt_s >= 0.0:
                raise ValueError(f"dt_s must be >= 0, got {dt_s!r}")
            self._per_period(dt_s)
        x = float(true_current_A)
        filtered = self._filtered_A
        if filtered is None or self.lag_s == 0.0:
            filtered = x
        else:
            filtered += self._lag_gain * (x - filtered)
        self._filtered_A = filtered
        reading = self.gain * filtered + self.offset_A
        if self.noise_A > 0.0:
            reading += self.noise_A * self._normal()
        if self.spike_rate_hz > 0.0 and self._uniform() < self._spike_p:
            reading += self.spike_A * (1.0 if self._uniform() < 0.5 else -1.0)
        return reading
