"""The drive's lag behind its target, from commanded and actual position (no tip needed)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def estimate_lag_s(t_s: NDArray[np.float64], cmd_deg: NDArray[np.float64],
                   pos_deg: NDArray[np.float64], max_lag_s: float = 0.5) -> float:
    """The delay that best maps commanded onto actual position (least squares over a grid)."""
    t = np.asarray(t_s, float)
    cmd = np.asarray(cmd_deg, float)
    pos = np.asarray(pos_deg, float)
    ok = np.isfinite(t) & np.isfinite(cmd) & np.isfinite(pos)
    t, cmd, pos = t[ok], cmd[ok], pos[ok]
    if t.size < 10:
        return 0.0
    dt = float(np.median(np.diff(t)))
    lags = np.arange(0.0, max_lag_s + 0.5 * dt, max(dt / 4.0, 1e-4))
    errors = [float(np.mean((np.interp(t - lag, t, cmd) - pos)[t > t[0] + max_lag_s] ** 2))
              for lag in lags]
    return float(lags[int(np.argmin(errors))])
