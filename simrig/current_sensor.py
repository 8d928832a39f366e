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

    Deterministic for a given ``seed``. ``measure`` is called once per control period.
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
        self._filtered_A: float | None = None

    def measure(self, dt_s: float, true_current_A: float) -> float:
        """The reading after ``dt_s`` more seconds of ``true_current_A`` (amperes)."""
        if not dt_s >= 0.0:
            raise ValueError(f"dt_s must be >= 0, got {dt_s!r}")
        x = float(true_current_A)
        if self._filtered_A is None or self.lag_s == 0.0:
            self._filtered_A = x
        else:
            self._filtered_A += (1.0 - math.exp(-dt_s / self.lag_s)) * (x - self._filtered_A)
        reading = self.gain * self._filtered_A + self.offset_A
        if self.noise_A > 0.0:
            reading += self.noise_A * float(self._rng.standard_normal())
        if self.spike_rate_hz > 0.0 and self._rng.random() < -math.expm1(
            -self.spike_rate_hz * dt_s
        ):
            reading += self.spike_A * (1.0 if self._rng.random() < 0.5 else -1.0)
        return reading
