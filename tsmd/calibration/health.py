"""Refusals for what is really wrong with a sweep, each named: a current sensor stuck or
saturated, a knob that slips, a motor that stalls.

These look at the raw readings (before spike removal and the low-pass, which would hide a stuck
or clipped sensor) and at the loaded stretch of each half-cycle. Thresholds are set so that the
real TEE acquisitions (quantised current, 2.69 mA steps: at most 10 equal readings in a row,
at most 0.2 % of the samples at the extreme) and the simulated catheters pass with wide margin.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from tsmd.calibration.errors import CalibrationError
from tsmd.calibration.signal import Conditioned, FloatArray


@dataclass(frozen=True)
class HealthLimits:
    """What a working current sensor and coupling never show."""

    stuck_min_s: float = 2.0
    """Identical readings for this long ..."""
    stuck_min_travel_deg: float = 10.0
    """... while the knob travels this far: the sensor is stuck."""
    saturated_fraction: float = 0.02
    """This share of the samples exactly at one of the largest readings, in separate runs, and
    none beyond it on its side: clipped."""
    slip_drop_fraction: float = 0.3
    """A loaded current falling by this share of its rise ..."""
    slip_drop_deg: float = 1.0
    """... within this much knob travel in the direction of motion: the knob slipped."""
    slip_min_noise: float = 8.0
    """A slip drop must also exceed this many noise sigmas."""


def _longest_equal_run(x: FloatArray) -> tuple[int, int]:
    """(start, length) of the longest run of exactly equal consecutive values."""
    same = np.concatenate([[False], np.diff(x) == 0, [False]])
    edges = np.diff(same.astype(np.int8))
    starts = np.flatnonzero(edges == 1)
    stops = np.flatnonzero(edges == -1)
    if starts.size == 0:
        return 0, 1
    lengths = stops - starts
    k = int(np.argmax(lengths))
    return int(starts[k]), int(lengths[k]) + 1


def check_sensor(t_s: FloatArray, pos_deg: FloatArray, current_A: FloatArray,
                 limits: HealthLimits | None = None) -> None:
    """Refuse a stuck or saturated current sensor (raw readings, NaNs ignored)."""
    lim = limits or HealthLimits()
    ok = np.isfinite(current_A) & np.isfinite(pos_deg)
    cur, pos, t = current_A[ok], pos_deg[ok], t_s[ok]
    if cur.size < 3:
        return
    # Clipped: one reading among the largest magnitudes recurs, in several separate runs (every
    # stroke that loads past the limit); a stuck sensor repeats one value in one run instead.
    values, counts = np.unique(cur, return_counts=True)
    k = int(np.argmax(counts))
    value, share = float(values[k]), float(counts[k]) / cur.size
    at = np.concatenate([[False], cur == value, [False]]).astype(np.int8)
    runs = int(np.sum(np.diff(at) == 1))
    large = abs(value) >= float(np.quantile(np.abs(cur), 0.9))
    # A clipped sensor reads nothing beyond its rail; a quantised current (2 mA steps) that
    # dwells near its peak repeats one large reading just as often but reads past it too.
    beyond = int(np.count_nonzero(cur > value if value > 0 else cur < value))
    if (share >= lim.saturated_fraction and large and runs >= 2 and beyond == 0
            and float(np.ptp(cur)) > 0):
        raise CalibrationError(
            f"the current sensor is saturated: {share:.0%} of the readings sit exactly at "
            f"{value * 1e3:.1f} mA, in {runs} separate stretches (clipped)")
    start, length = _longest_equal_run(cur)
    stop = start + length - 1
    duration = float(t[stop] - t[start])
    travel = float(np.ptp(pos[start:stop + 1]))
    if duration >= lim.stuck_min_s and travel >= lim.stuck_min_travel_deg:
        raise CalibrationError(
            f"the current sensor is stuck at {cur[start] * 1e3:.1f} mA from t={t[start]:.1f} s "
            f"to t={t[stop]:.1f} s while the knob moved {travel:.0f} deg")


def find_slip(grid_deg: FloatArray, yg: FloatArray, start_k: int, noise_A: float,
              limits: HealthLimits | None = None) -> str | None:
    """A loaded current that drops while the knob moves on (the knob slipped), described; None
    when the load only grows.

    ``yg`` is the direction-signed filtered current on a uniform angle grid; from ``start_k``
    (the release after a reversal has settled) a healthy catheter's load only grows with the
    travel. One such drop can be a disturbance; :func:`check_slips` refuses a sweep where most
    loaded strokes show one.
    """
    lim = limits or HealthLimits()
    if start_k >= yg.size - 2:
        return None
    step = float(grid_deg[1] - grid_deg[0])
    loaded = yg[start_k:]
    rise = float(loaded.max() - loaded[0])
    if rise <= 0:
        return None
    width = max(1, round(lim.slip_drop_deg / step))
    padded = np.concatenate([loaded, np.full(width, loaded[-1])])
    # Largest fall from any point to the lowest value within the next `width` grid steps.
    falls = loaded - sliding_window_view(padded[1:], width).min(axis=1)
    k = int(np.argmax(falls))
    drop = float(falls[k])
    if drop > lim.slip_drop_fraction * rise and drop > lim.slip_min_noise * noise_A:
        return (f"the loaded current drops by {drop * 1e3:.0f} mA within {lim.slip_drop_deg:g} "
                f"deg at {grid_deg[start_k + k]:.1f} deg while the knob moves on")
    return None


def check_slips(findings: Sequence[str | None]) -> None:
    """Refuse a sweep where most loaded strokes (at least two) show a slip: a coupling or
    tendon that slips does so on every stroke past its holding torque."""
    slips = [f for f in findings if f]
    if len(slips) >= 2 and 2 * len(slips) >= len(findings):
        raise CalibrationError(
            f"the knob slips (coupling or tendon): on {len(slips)} of {len(findings)} loaded "
            f"strokes {slips[0]}")


def check_following(data: Conditioned, min_travel_deg: float, min_follow_ratio: float,
                    max_lag_deg: float) -> None:
    """A stalled or lagging knob makes the current meaningless: refuse it, saying how much."""
    commanded = float(np.ptp(data.cmd_deg))
    actual = float(np.ptp(data.pos_deg))
    if commanded > min_travel_deg and actual < min_follow_ratio * commanded:
        raise CalibrationError(
            f"the knob did not follow the command (moved {actual:.1f} deg of {commanded:.1f} "
            f"deg commanded): motor stalled or blocked")
    lag = np.abs(data.cmd_deg - data.pos_deg)
    if float(lag.max()) > max_lag_deg:
        k = int(np.argmax(lag))
        raise CalibrationError(
            f"the knob lags the command by {lag[k]:.1f} deg at t={data.t_s[k]:.2f} s "
            f"(> {max_lag_deg:g} deg): motor stalled or too slow")


def check_signal(data: Conditioned, halves: Sequence[tuple[int, int, int, float]],
                 min_snr: float) -> None:
    """No half-cycle (direction, start, stop, SNR) shows a load: tell a missing current signal
    from a catheter that never leaves its dead zone. A working sensor still shows the drive's
    friction, which flips with the direction of motion; a disconnected one reads noise that
    does not."""
    if not halves or any(snr >= min_snr for *_, snr in halves):
        return
    signed = np.concatenate([d * data.current_filtered_A[a:b] for d, a, b, _ in halves])
    friction = float(np.median(signed))
    noise = max(data.filtered_noise_A, 1e-12)
    best = max((snr for *_, snr in halves if math.isfinite(snr)), default=math.nan)
    if abs(friction) < min_snr * noise:
        raise CalibrationError(
            f"no current signal: the current does not follow the motion (direction-dependent "
            f"part {friction * 1e3:.1f} mA, noise {noise * 1e3:.1f} mA); check the drive's "
            "current feedback")
    raise CalibrationError(
        f"the sweep never leaves the dead zone: the current shows the drive's friction "
        f"({friction * 1e3:.1f} mA) but no load in any half-cycle (best rise {best:.1f} x "
        f"noise < {min_snr:g}); tendon broken or slack beyond the travel")
