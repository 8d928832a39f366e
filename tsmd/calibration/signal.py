"""Conditioning of logged sweeps before identification: gaps, spikes, the paper's low-pass.

Everything here is a pure function on arrays. A problem the data cannot recover from (a long gap,
too few samples) raises :class:`CalibrationError` naming it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import signal

from tsmd.calibration.errors import CalibrationError

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Conditioned:
    """A sweep on a uniform time grid with the current cleaned and low-passed."""

    t_s: FloatArray
    cmd_deg: FloatArray
    pos_deg: FloatArray
    current_A: FloatArray
    """Current after gap filling and spike removal (before the low-pass)."""
    current_filtered_A: FloatArray
    sample_rate_hz: float
    noise_A: float
    """Robust standard deviation of the white noise on the unfiltered current."""
    filtered_noise_A: float
    """The same after the low-pass (approximation for a white spectrum)."""
    notes: tuple[str, ...]


def robust_sigma(x: FloatArray) -> float:
    """Standard deviation estimated from the median absolute deviation (ignores outliers)."""
    if x.size == 0:
        return 0.0
    return float(1.4826 * np.median(np.abs(x - np.median(x))))


def walsh_median(values: FloatArray) -> float:
    """Hodges-Lehmann location: the median of every pair's mean (each value with itself
    included). As efficient as the mean on normal scatter (95 %), where the median of a few
    half-cycles wastes a third of them (a re-sweep's third value would barely narrow it), and
    still robust: one stray value among four moves it by a fraction of its distance. NaN when
    empty."""
    v = np.asarray(values, dtype=float)
    if v.size == 0:
        return float("nan")
    i, j = np.triu_indices(v.size)
    return float(np.median(0.5 * (v[i] + v[j])))


def white_noise_sigma(x: FloatArray) -> float:
    """Noise level of a signal with a smooth trend, from its first differences."""
    if x.size < 3:
        return 0.0
    return robust_sigma(np.diff(x)) / np.sqrt(2.0)


def fill_gaps(t_s: FloatArray, values: FloatArray, name: str, max_gap_s: float) -> FloatArray:
    """Interpolate NaN runs no longer than ``max_gap_s``; a longer run is an error."""
    bad = ~np.isfinite(values)
    if not bad.any():
        return values
    if bad.all():
        raise CalibrationError(f"{name} has no valid sample")
    edges = np.diff(np.concatenate([[0], bad.astype(np.int8), [0]]))
    starts = np.flatnonzero(edges == 1)
    stops = np.flatnonzero(edges == -1)
    for a, b in zip(starts, stops, strict=True):
        left = t_s[a - 1] if a > 0 else t_s[a]
        right = t_s[b] if b < len(t_s) else t_s[b - 1]
        if right - left > max_gap_s:
            raise CalibrationError(
                f"{name} is missing {b - a} samples from t={t_s[a]:.3f} s to t={t_s[b - 1]:.3f} s "
                f"({right - left:.2f} s > {max_gap_s:g} s allowed)")
    good = ~bad
    return np.interp(t_s, t_s[good], values[good])


def remove_spikes(x: FloatArray, window: int = 7, threshold: float = 6.0) -> tuple[FloatArray, int]:
    """Replace isolated outliers by the running median (Hampel filter); return how many."""
    if x.size < window:
        return x, 0
    med = signal.medfilt(x, kernel_size=window)
    residual = x - med
    sigma = robust_sigma(residual)
    if sigma <= 0:
        return x, 0
    spikes = np.abs(residual) > threshold * sigma
    out = np.where(spikes, med, x)
    return out, int(spikes.sum())


def lowpass(x: FloatArray, sample_rate_hz: float, cutoff_hz: float = 20.0,
            order: int = 3) -> tuple[FloatArray, str | None]:
    """The paper's zero-phase Butterworth; skipped (with the reason) when it cannot apply."""
    nyquist = 0.5 * sample_rate_hz
    if cutoff_hz >= 0.95 * nyquist:
        return x.copy(), (f"low-pass skipped: {sample_rate_hz:.1f} Hz sampling cannot carry a "
                          f"{cutoff_hz:g} Hz cutoff (Nyquist {nyquist:.1f} Hz)")
    sos = signal.butter(order, cutoff_hz, btype="low", fs=sample_rate_hz, output="sos")
    padlen = 3 * (2 * len(sos) + 1)
    if x.size <= padlen:
        return x.copy(), f"low-pass skipped: only {x.size} samples"
    return signal.sosfiltfilt(sos, x), None


def condition(t_s: FloatArray, cmd_deg: FloatArray, pos_deg: FloatArray, current_A: FloatArray,
              *, cutoff_hz: float = 20.0, order: int = 3, max_gap_s: float = 0.5,
              min_samples: int = 50) -> Conditioned:
    """Validate, fill short gaps, put on a uniform grid, remove spikes and low-pass the current."""
    arrays = [np.asarray(a, dtype=float).ravel() for a in (t_s, cmd_deg, pos_deg, current_A)]
    n = len(arrays[0])
    if any(len(a) != n for a in arrays):
        raise CalibrationError(
            "t, cmd, pos and current must have the same length, got "
            + ", ".join(str(len(a)) for a in arrays))
    t, cmd, pos, cur = arrays
    keep = np.isfinite(t)
    if keep.sum() < min_samples:
        raise CalibrationError(f"only {int(keep.sum())} samples with a time stamp "
                               f"(need >= {min_samples})")
    if not keep.all():  # else the recording's own arrays: no copy of a sweep per stage
        t, cmd, pos, cur = (a[keep] for a in (t, cmd, pos, cur))
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.flatnonzero(dt <= 0)[0])
        raise CalibrationError(f"time is not strictly increasing at sample {k + 1} "
                               f"(t={t[k + 1]:.4f} s)")
    notes: list[str] = []
    cmd = fill_gaps(t, cmd, "commanded position", max_gap_s)
    pos = fill_gaps(t, pos, "actual position", max_gap_s)
    missing = int((~np.isfinite(cur)).sum())
    cur = fill_gaps(t, cur, "current", max_gap_s)
    if missing:
        notes.append(f"{missing} missing current samples interpolated")
    period = float(np.median(dt))
    if dt.max() > max_gap_s:
        k = int(np.argmax(dt))
        raise CalibrationError(f"no sample between t={t[k]:.3f} s and t={t[k + 1]:.3f} s "
                               f"({dt[k]:.2f} s > {max_gap_s:g} s allowed)")
    if dt.max() > 1.5 * period:
        grid = t[0] + period * np.arange(int(np.floor((t[-1] - t[0]) / period)) + 1)
        cmd, pos, cur = (np.interp(grid, t, a) for a in (cmd, pos, cur))
        notes.append(f"resampled onto a uniform {period * 1e3:.2f} ms grid (time gaps)")
        t = grid
    rate = 1.0 / period
    cur, n_spikes = remove_spikes(cur)
    if n_spikes:
        notes.append(f"{n_spikes} current spikes removed")
    filtered, note = lowpass(cur, rate, cutoff_hz, order)
    if note:
        notes.append(note)
    noise = white_noise_sigma(cur)
    filtered_noise = noise * float(np.sqrt(min(1.0, 2.0 * cutoff_hz / rate)))
    return Conditioned(t, cmd, pos, cur, filtered, rate, noise, filtered_noise, tuple(notes))
