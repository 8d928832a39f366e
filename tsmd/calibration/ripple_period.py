"""A handle's torque ripple period read from the motor current (session 23, a diagnostic).

A detent's notches or a gear's teeth put a ripple in the knob's torque that is locked to the
knob's angle; the edge fit averages it out over one period (:func:`tsmd.calibration.pieces.
period_mean`) where the data sheet carries the period. A manufacturer knows it; a user with a new
handle may not. On the loaded ramp (past the dead-zone edge, where the current is large) each
half-cycle's current less a cubic trend in the knob angle is the residual; their mean
autocorrelation over the knob angle proposes a period (its highest peak). Curvature the cubic
leaves, and a sheath's stick-slip, can also repeat within one ramp, so the period is only taken
where it also locks the two directions together: the two ramps of one knob lie on opposite sides
of the dead zone, and a ripple locked to the knob's angle makes the mean residual of one
direction match the other's shifted by whole periods (and oppose it at half periods). The lock
is tested against the same statistic with the second direction's residual phase-randomised.

On unit 0 of the fifteen plants (plant-alone +-90 deg sweeps; docs/calibration.md "Session 23")
the autocorrelation proposes warmgear's tooth pitch (24.3-24.6 deg against 24) and snakedent's
notch spacing (14.6-15.4 against 15) with peaks of 0.59-0.71, the other thirteen plants' peaks
are 0.08-0.13 but coilpipe's 0.42-0.46 (at 3 deg, decaying over its repeats); but the lock is
one phase comparison per sweep, which a phase-randomised null matches a fifth to a half of the
time even for warmgear (p 0.20-0.45): on +-90 deg sweeps a 24 deg period repeats about twice
within a ramp, too few to test. So :func:`handle_period` accepts nothing there, and the period
stays a design constant given to the data sheet (``tsmd datasheet --torque-ripple-period-deg``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tsmd.calibration.identify import analyse_half_cycle, resample_on_angle, split_half_cycles
from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.signal import Conditioned, FloatArray

RIPPLE_STEP_DEG = 0.25
"""The knob-angle grid the residuals are read on."""
RAMP_START_DEG = 5.0
"""A ramp's residual starts this far past the half-cycle's dead-zone edge (the hinge's corner
would otherwise be the residual's largest feature)."""
RAMP_END_MARGIN_DEG = 4.0
"""And ends this far before the reversal (the motor's deceleration)."""
MIN_RAMP_DEG = 30.0
"""A shorter ramp is left out: too short to hold one period and the trend apart."""
MIN_PERIOD_DEG = 3.0
"""Periods shorter than this are the current's low-pass and noise, not a handle's ripple."""
MIN_OVERLAP_DEG = 20.0
"""The shifted directions must overlap by at least this much to be compared at a shift."""
SURROGATES = 199
"""Phase-randomised copies of the second direction: the lock's null distribution."""
SIGNIFICANCE = 0.01
"""The lock counts where at most this share of the null reaches it."""
PERIOD_AGREEMENT = 0.1
"""Sweeps agree on a period within this share of it."""


@dataclass(frozen=True)
class RippleRead:
    """One sweep's reading: the autocorrelation's period, its lock and the lock's null."""

    candidate_deg: float
    """The highest peak of the ramps' mean residual autocorrelation (NaN: none)."""
    autocorrelation: float
    period_deg: float
    """The candidate refined where the directions lock best (NaN: no lock could be read)."""
    lock: float
    p_value: float
    ramps: int

    @property
    def locked(self) -> bool:
        return math.isfinite(self.period_deg) and self.p_value <= SIGNIFICANCE

    def text(self) -> str:
        return (f"{self.ramps} ramps, autocorrelation peak {self.autocorrelation:+.2f} at "
                f"{self.candidate_deg:.2f} deg, lock {self.lock:+.2f} at "
                f"{self.period_deg:.2f} deg (p {self.p_value:.3f})")


def ramp_residuals(data: Conditioned, opts: IdentifyOptions | None = None
                   ) -> dict[int, list[tuple[FloatArray, FloatArray]]]:
    """Per direction, each half-cycle's loaded ramp as (knob angle on the grid, current less
    a cubic trend), the angle absolute (not direction-signed)."""
    opts = opts or IdentifyOptions()
    out: dict[int, list[tuple[FloatArray, FloatArray]]] = {1: [], -1: []}
    for direction, a, b, after in split_half_cycles(data.cmd_deg, 10.0):
        half = analyse_half_cycle(data, direction, a, b, after, opts)
        if not math.isfinite(half.edge_deg):
            continue
        grid, yg = resample_on_angle(data.pos_deg[a:b], direction * data.current_filtered_A[a:b],
                                     direction, RIPPLE_STEP_DEG)
        lo = int(np.searchsorted(grid, direction * half.edge_deg + RAMP_START_DEG))
        hi = grid.size - round(RAMP_END_MARGIN_DEG / RIPPLE_STEP_DEG)
        if (hi - lo) * RIPPLE_STEP_DEG < MIN_RAMP_DEG:
            continue
        x, y = grid[lo:hi], yg[lo:hi]
        u = (x - x.mean()) / (x[-1] - x[0])
        residual = y - np.polyval(np.polyfit(u, y, 3), u)
        angle = np.round(direction * x / RIPPLE_STEP_DEG) * RIPPLE_STEP_DEG
        order = np.argsort(angle)
        out[direction].append((angle[order], residual[order]))
    return out


def autocorrelation(residual: FloatArray, max_lag: int) -> FloatArray:
    """Normalised autocorrelation at lags 0..max_lag-1 (each lag's mean product over its
    overlap, over the lag-0 one)."""
    r = residual - residual.mean()
    c = np.array([float(np.dot(r[:r.size - k], r[k:])) / (r.size - k) for k in range(max_lag)])
    return c / c[0] if c[0] > 0.0 else np.zeros(max_lag)


def candidate_period(ramps: Sequence[FloatArray]) -> tuple[float, float]:
    """The highest local peak of the ramps' mean autocorrelation at a lag of at least
    ``MIN_PERIOD_DEG`` and at most half the shortest ramp: (period deg, its value); NaN where
    there is none."""
    if not ramps:
        return math.nan, math.nan
    max_lag = min(r.size for r in ramps) // 2
    mean = np.mean([autocorrelation(r, max_lag) for r in ramps], axis=0)
    first = math.ceil(MIN_PERIOD_DEG / RIPPLE_STEP_DEG)
    peaks = [k for k in range(max(first, 1), max_lag - 1)
             if mean[k] > mean[k - 1] and mean[k] >= mean[k + 1]]
    if not peaks:
        return math.nan, math.nan
    best = max(peaks, key=lambda k: mean[k])
    # the parabola through the peak and its neighbours: a grid step is too coarse for the
    # several periods between the two directions' ramps
    left, mid, right = mean[best - 1], mean[best], mean[best + 1]
    curve = left - 2.0 * mid + right
    shift = 0.5 * (left - right) / curve if curve < 0.0 else 0.0
    return (best + shift) * RIPPLE_STEP_DEG, float(mean[best])


def direction_mean(ramps: Sequence[tuple[FloatArray, FloatArray]]
                   ) -> tuple[FloatArray, FloatArray] | None:
    """The direction's residuals averaged on the angles every one of its ramps covers (a ripple
    locked to the angle adds up, noise does not); None where they share too little."""
    if not ramps:
        return None
    lo = max(float(a[0]) for a, _ in ramps)
    hi = min(float(a[-1]) for a, _ in ramps)
    if hi - lo < MIN_RAMP_DEG:
        return None
    angle = np.arange(round(lo / RIPPLE_STEP_DEG), round(hi / RIPPLE_STEP_DEG) + 1,
                      dtype=np.float64) * RIPPLE_STEP_DEG
    mean = np.mean([np.interp(angle, a, r) for a, r in ramps], axis=0)
    return angle, np.asarray(mean, dtype=np.float64)


def _shifted_correlation(angle_a: FloatArray, a: FloatArray, angle_b: FloatArray,
                         b: FloatArray, shift_deg: float) -> float:
    """Correlation of ``a`` with ``b`` moved by ``shift_deg`` over their overlap (NaN: less
    than ``MIN_OVERLAP_DEG``)."""
    lo = max(float(angle_a[0]), float(angle_b[0]) + shift_deg)
    hi = min(float(angle_a[-1]), float(angle_b[-1]) + shift_deg)
    if hi - lo < MIN_OVERLAP_DEG:
        return math.nan
    x = np.arange(lo, hi, RIPPLE_STEP_DEG)
    u = np.interp(x, angle_a, a)
    v = np.interp(x - shift_deg, angle_b, b)
    u, v = u - u.mean(), v - v.mean()
    den = math.sqrt(float(np.dot(u, u)) * float(np.dot(v, v)))
    return float(np.dot(u, v)) / den if den > 0.0 else math.nan


def lock(angle_a: FloatArray, a: FloatArray, angle_b: FloatArray, b: FloatArray,
         period_deg: float) -> float:
    """How far ``b`` shifted by whole periods matches ``a`` and shifted by half periods opposes
    it: the mean over the shifts that overlap of (C(k P) - C((k + 1/2) P)) / 2, signed so a
    ripple that changes sign with the direction locks too; NaN where no shift overlaps."""
    if not period_deg > 0.0:
        return math.nan
    span = float(max(angle_a[-1], angle_b[-1]) - min(angle_a[0], angle_b[0]))
    n = int(span / period_deg) + 2
    on, off = [], []
    for k in range(-n, n + 1):
        c_on = _shifted_correlation(angle_a, a, angle_b, b, k * period_deg)
        c_off = _shifted_correlation(angle_a, a, angle_b, b, (k + 0.5) * period_deg)
        if math.isfinite(c_on) and math.isfinite(c_off):
            on.append(c_on)
            off.append(c_off)
    if not on:
        return math.nan
    d = np.asarray(on) - np.asarray(off)
    sign = 1.0 if np.mean(on) >= 0.0 else -1.0
    return float(sign * np.mean(d) / 2.0)


def phase_randomised(x: FloatArray, rng: np.random.Generator) -> FloatArray:
    """``x`` with its Fourier amplitudes kept and its phases drawn at random."""
    spectrum = np.fft.rfft(x - x.mean())
    phases = rng.uniform(0.0, 2.0 * math.pi, spectrum.size)
    phases[0] = 0.0
    if x.size % 2 == 0:
        phases[-1] = 0.0
    return np.fft.irfft(np.abs(spectrum) * np.exp(1j * phases), n=x.size)


def sweep_ripple(data: Conditioned, opts: IdentifyOptions | None = None,
                 seed: int = 0) -> RippleRead:
    """One sweep's ripple reading (:class:`RippleRead`); ``seed`` draws the null's phases."""
    ramps = ramp_residuals(data, opts)
    residuals = [r for d in (1, -1) for _, r in ramps[d]]
    candidate, rho = candidate_period(residuals)
    pos, neg = direction_mean(ramps[1]), direction_mean(ramps[-1])
    if not math.isfinite(candidate) or pos is None or neg is None:
        return RippleRead(candidate, rho, math.nan, math.nan, 1.0, len(residuals))
    observed = lock(pos[0], pos[1], neg[0], neg[1], candidate)
    if not math.isfinite(observed):
        return RippleRead(candidate, rho, math.nan, math.nan, 1.0, len(residuals))
    rng = np.random.default_rng(seed)
    null = [lock(pos[0], pos[1], neg[0], phase_randomised(neg[1], rng), candidate)
            for _ in range(SURROGATES)]
    reached = sum(1 for x in null if math.isfinite(x) and x >= observed)
    return RippleRead(candidate, rho, candidate, observed, (1 + reached) / (1 + SURROGATES),
                      len(residuals))


def handle_period(reads: Sequence[RippleRead]) -> float | None:
    """The handle's ripple period where every sweep locks at the same period (within
    ``PERIOD_AGREEMENT``): their mean, rounded to the grid; else None (no ripple, or none
    that every sweep shows)."""
    if not reads or not all(r.locked for r in reads):
        return None
    periods = np.array([r.period_deg for r in reads])
    mean = float(np.mean(periods))
    if np.max(np.abs(periods - mean)) > PERIOD_AGREEMENT * mean:
        return None
    return round(mean / RIPPLE_STEP_DEG) * RIPPLE_STEP_DEG
