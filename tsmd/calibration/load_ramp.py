"""The loaded current ramp of one sweep, per side: its zero-tension point and backlash gain.

The current moving through the dead zone is friction only (no tendon loaded); on the loaded
ramp the same friction acts, so tension is current minus that level. The ramp (from
``RAMP_START_DEG`` past the edge to ``RAMP_END_DEG`` before the turn) fitted by a line and
extrapolated to zero tension gives ``x0``; ``beta = B_A / (A - x0)``. One estimator for the
calibration (:mod:`tsmd.calibration.tension_play_fit`) and the data sheet's
``reference_backlash_gain``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tsmd.compensation.tension_play_params import BETA_RANGE

FloatArray = NDArray[np.float64]
RAMP_START_DEG = 10.0
"""The loaded ramp is fitted from this far past the dead-zone edge (the knee is curved) ..."""
RAMP_END_DEG = 5.0
"""... to this far before the turn (the current lags and the drive slows there)."""
PLATEAU_MARGIN_DEG = 5.0
MIN_RAMP_SAMPLES = 50


@dataclass(frozen=True)
class SideFit:
    """What one side of one sweep gave."""

    dead_zone_deg: float
    backlash_deg: float
    amplitude_deg: float
    zero_load_deg: float
    backlash_gain: float


def friction_current_A(pos_deg: FloatArray, current_A: FloatArray, d_pos: float, d_neg: float,
                       direction: int) -> float:
    """The current moving through the dead zone in ``direction``: no tendon is loaded, only the
    knob's and the motor's friction act (and any offset of the sensor). The loaded ramp of the
    same direction carries the same friction, so tension = current minus this."""
    v = np.gradient(pos_deg)
    inside = (pos_deg > d_neg + PLATEAU_MARGIN_DEG) & (pos_deg < d_pos - PLATEAU_MARGIN_DEG)
    moving = current_A[inside & (direction * v > 0)]
    if moving.size < 10:
        raise ValueError("the sweep does not cross the dead zone both ways")
    return float(np.median(moving))


def fit_side(pos_deg: FloatArray, current_A: FloatArray, sign: int, dead_zone_deg: float,
             backlash_deg: float, zero_A: float) -> SideFit:
    """x0 and beta of one side (``sign`` +1: positive side, loaded while moving up)."""
    v = np.gradient(pos_deg)
    amplitude = float(np.max(sign * pos_deg)) * sign
    x = sign * pos_deg
    sel = ((sign * v > 0) & (x > sign * dead_zone_deg + RAMP_START_DEG)
           & (x < sign * amplitude - RAMP_END_DEG))
    if np.count_nonzero(sel) < MIN_RAMP_SAMPLES:
        raise ValueError(f"too few samples on the loaded ramp of the {'+' if sign > 0 else '-'} "
                         "side (amplitude too small for the dead zone)")
    slope, intercept = np.polyfit(pos_deg[sel], current_A[sel] - zero_A, 1)
    if not slope > 0:  # the current grows with the position on both sides (sign of load)
        raise ValueError("the loaded current does not grow with the load")
    x0 = float(-intercept / slope)
    run = sign * (amplitude - x0)
    if not run > backlash_deg > 0:
        raise ValueError(f"backlash {backlash_deg:.1f} deg does not fit a load ramp of "
                         f"{run:.1f} deg")
    beta = min(max(backlash_deg / run, BETA_RANGE[0]), BETA_RANGE[1])
    return SideFit(dead_zone_deg, backlash_deg, amplitude, x0, beta)


def fit_sweep_sides(pos_deg: FloatArray, current_A: FloatArray, dead_zone_pos_deg: float,
                    dead_zone_neg_deg: float, backlash_pos_deg: float, backlash_neg_deg: float
                    ) -> tuple[SideFit, SideFit]:
    """Both sides of one sweep (+, -); samples with a non-finite value are dropped. The data
    sheet's ``reference_backlash_gain`` comes from the same function (one estimator)."""
    pos = np.asarray(pos_deg, float)
    cur = np.asarray(current_A, float)
    ok = np.isfinite(pos) & np.isfinite(cur)
    pos, cur = pos[ok], cur[ok]
    fits = []
    for sign, d, b in ((1, dead_zone_pos_deg, backlash_pos_deg),
                       (-1, dead_zone_neg_deg, backlash_neg_deg)):
        zero = friction_current_A(pos, cur, dead_zone_pos_deg, dead_zone_neg_deg, sign)
        fits.append(fit_side(pos, cur, sign, float(d), float(b), zero))
    return fits[0], fits[1]


__all__ = ["MIN_RAMP_SAMPLES", "PLATEAU_MARGIN_DEG", "RAMP_END_DEG", "RAMP_START_DEG", "SideFit",
           "fit_side", "fit_sweep_sides", "friction_current_A"]
