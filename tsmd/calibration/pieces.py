"""Detectors on the current of one half-cycle against knob angle: linear pieces (ruptures PELT),
the constant-current phase, the dead-zone edge (knee, least-squares fit) and the smoothed
crossings the backlash rules use (:mod:`tsmd.calibration.release`).

Each works on the direction-signed current resampled on a uniform grid of knob angle; indices
are into that grid. :mod:`tsmd.calibration.identify` strings them together per half-cycle.
"""

from __future__ import annotations

import math

import numpy as np
import ruptures as rpt

from tsmd.calibration.branch_fit import fit_edge
from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.signal import FloatArray


def slope_per_deg(y: FloatArray, step: float) -> float:
    if y.size < 2:
        return 0.0
    return float(np.polyfit(np.arange(y.size) * step, y, 1)[0])


def linear_pieces(yg: FloatArray, noise: float, opts: IdentifyOptions) -> list[tuple[int, int]]:
    """Linear pieces of the current against angle (ruptures PELT, continuous linear cost)."""
    penalty = max(opts.penalty_k * noise ** 2 * math.log(max(yg.size, 2)), 1e-15)
    jump = max(2, yg.size // 400)
    algo = rpt.Pelt(model="clinear", min_size=2, jump=jump).fit(yg)
    bkps = [int(b) for b in algo.predict(pen=penalty)]
    return list(zip([0, *bkps[:-1]], bkps, strict=True))


def flat_pieces(yg: FloatArray, step: float, pieces: list[tuple[int, int]],
                 opts: IdentifyOptions) -> list[bool] | None:
    """Which pieces are flat: rising slower than ``flat_slope_fraction`` of the loaded ramp
    (the slope over the last quarter of the travel), or falling gently (a fall as steep as the
    ramp is the peak after a reversal coming down, not a plateau). None without a ramp."""
    loaded = slope_per_deg(yg[int(0.75 * yg.size):], step)
    if loaded <= 0:
        return None
    slopes = [slope_per_deg(yg[a:b], step) for a, b in pieces]
    return [-loaded < s < opts.flat_slope_fraction * loaded for s in slopes]


def constant_phase(pieces: list[tuple[int, int]], flat: list[bool], step: float,
                   opts: IdentifyOptions, yg: FloatArray | None = None,
                   loaded_swing: float | None = None) -> tuple[int, int] | None:
    """The constant-current stretch before the dead-zone edge (start, stop on the grid): the last
    run of flat pieces at least ``min_level_deg`` long (else the longest run).

    Not simply the longest: the release level after a reversal is flat too, and where the tip
    re-enters the dead zone the released tendon drops its last tension, a short step that cuts
    the two apart; the release run can then be the longer one (fast sweeps, phi2 at +90 deg).
    Nor a run on the loaded branch: a geared handle's current climbs in steps (one per tooth
    of mesh), flat between them. With the current ``yg`` and the knob's ``loaded_swing`` (half
    the sweep's current range), a run standing more than half that swing above the lowest long
    run is loaded, not slack, and is passed over.
    """
    runs = flat_runs(pieces, flat)
    long_enough = [r for r in runs if (r[1] - r[0]) * step >= opts.min_level_deg]
    if long_enough and yg is not None and loaded_swing is not None:
        levels = [float(np.median(yg[a:b])) for a, b in long_enough]
        slack = min(levels)
        long_enough = [r for r, level in zip(long_enough, levels, strict=True)
                       if level - slack <= 0.5 * loaded_swing]
    if long_enough:
        return long_enough[-1]
    return max(runs, key=lambda r: r[1] - r[0], default=None)


def flat_runs(pieces: list[tuple[int, int]], flat: list[bool]) -> list[tuple[int, int]]:
    """Maximal runs of consecutive flat pieces, as (start, stop) on the grid, in order."""
    runs: list[tuple[int, int]] = []
    k = 0
    while k < len(pieces):
        if not flat[k]:
            k += 1
            continue
        j = k
        while j + 1 < len(pieces) and flat[j + 1]:
            j += 1
        runs.append((pieces[k][0], pieces[j][1]))
        k = j + 1
    return runs


def knee_edge(yg: FloatArray, step: float, pieces: list[tuple[int, int]], rise_k: int,
          opts: IdentifyOptions) -> int:
    """Beyond the paper: where the steep first rise (the tendon stretching while the tip is
    still held) turns into the loaded ramp (the tip moving). No steep part: the rise itself."""
    loaded = slope_per_deg(yg[int(0.75 * yg.size):], step)
    limit = rise_k + int(opts.max_knee_deg / step)
    steep = False
    for a, b in pieces:
        if b <= rise_k:
            continue
        if a >= limit:
            break
        slope = slope_per_deg(yg[max(a, rise_k):b], step)
        if slope > opts.knee_slope_ratio * loaded:
            steep = True
        elif steep:
            return max(a, rise_k)
    return rise_k


def fitted_edge(grid: FloatArray, yg: FloatArray, plateau_start: int, rise_k: int,
                 noise: float, opts: IdentifyOptions) -> int:
    """The edge as the least-squares line intersection around the rise the pieces show
    (:func:`tsmd.calibration.branch_fit.fit_edge`); the rise itself when nothing fits."""
    step = float(grid[1] - grid[0])
    a = max(plateau_start, rise_k - round(opts.fit_before_deg / step))
    b = min(yg.size, rise_k + round(opts.fit_after_deg / step))
    x, y = grid[a:b], yg[a:b]
    if opts.torque_ripple_period_deg:
        y = ripple_removed(grid, yg, opts.torque_ripple_period_deg)[a:b]
    fit = fit_edge(x, y, noise, knee_slope_ratio=opts.knee_slope_ratio,
                   max_knee_deg=opts.max_knee_deg, penalty_k=opts.penalty_k,
                   curve_check=opts.edge_curve,
                   search_step_deg=step)
    if fit is None:
        return rise_k
    return min(int(np.searchsorted(grid, fit.edge_deg)), yg.size - 1)


def period_mean(grid: FloatArray, yg: FloatArray, a: int, b: int,
                period_deg: float) -> tuple[FloatArray, FloatArray]:
    """``grid[a:b]`` and the current there averaged over one ripple period centred on each
    sample (a periodic ripple averages out, a straight line stays; the whole half-cycle
    supplies the samples either side), trimmed where the period runs off the half-cycle."""
    step = float(grid[1] - grid[0])
    half = max(1, round(0.5 * period_deg / step))
    lo, hi = max(a, half), min(b, yg.size - half)
    if hi - lo < 8:
        return grid[a:b], yg[a:b]
    sums = np.concatenate([[0.0], np.cumsum(yg)])
    k = np.arange(lo, hi)
    mean = (sums[k + half + 1] - sums[k - half]) / (2 * half + 1)
    return grid[lo:hi], mean


def ripple_removed(grid: FloatArray, yg: FloatArray, period_deg: float) -> FloatArray:
    """``yg`` less the ripple it carries with ``period_deg`` (a detent's notches): the current's
    departure from its one-period mean (:func:`period_mean`) folded on the period over the
    whole half-cycle, its median per phase. Averaging alone spreads the engagement's corner
    over a period (snakedent: edges read 1.6-2.1 deg inward on a detent-free unit, varying
    with where the notches lie); the departure near that corner is the corner's own, one or
    two periods of the half-cycle's dozen, which the median leaves out."""
    step = float(grid[1] - grid[0])
    x, smooth = period_mean(grid, yg, 0, yg.size, period_deg)
    if x.size == yg.size:  # too short a half-cycle for one period either side
        return yg
    start = round((float(x[0]) - float(grid[0])) / step)
    departure = yg[start:start + x.size] - smooth
    bins = max(1, round(period_deg / step))
    phase = np.floor(np.mod(x, period_deg) / step + 1e-9).astype(int) % bins
    template = np.array([float(np.median(departure[phase == b])) if np.any(phase == b)
                         else 0.0 for b in range(bins)])
    template -= template.mean()
    return yg - template[np.floor(np.mod(grid, period_deg) / step + 1e-9).astype(int) % bins]


def smooth_crossing(grid: FloatArray, yg: FloatArray, k: int, target: float,
                    half_deg: float) -> int:
    """Where a quadratic fitted to the current over ``half_deg`` either side of ``k`` crosses
    ``target`` upwards (nearest crossing; re-centred there, up to 4 times).

    Near the release level the current approaches it slowly, so sensor noise of a few mA moves
    the first sample above a share of the swing by degrees; a curve fitted over a few degrees
    averages that noise and leaves the trend.
    """
    for _ in range(4):
        fit = _local_quadratic(grid, yg, k, half_deg)
        if fit is None:
            return k
        a, b, coef = fit
        f = np.polyval(coef, grid[a:b] - grid[k]) - target
        ups = np.flatnonzero((f[:-1] < 0.0) & (f[1:] >= 0.0))
        if ups.size:
            k_new = a + int(ups[np.argmin(np.abs(ups + a - k))]) + 1
        else:
            k_new = a if f[0] >= 0.0 else b - 1
        if k_new == k:
            break
        k = k_new
    return k


def smooth_value(grid: FloatArray, yg: FloatArray, k: int, half_deg: float) -> float:
    """The current at ``grid[k]`` read off a quadratic fitted over ``half_deg`` either side
    (as :func:`smooth_crossing` reads it: a few mA of noise otherwise move a share by 1 %)."""
    fit = _local_quadratic(grid, yg, k, half_deg)
    return float(yg[k]) if fit is None else float(np.polyval(fit[2], 0.0))


def _local_quadratic(grid: FloatArray, yg: FloatArray, k: int, half_deg: float
                     ) -> tuple[int, int, FloatArray] | None:
    """The samples ``a:b`` within ``half_deg`` of ``grid[k]`` and a quadratic fitted to them in
    ``grid - grid[k]``; None when fewer than 6 samples are there."""
    width = round(half_deg / float(grid[1] - grid[0]))
    a, b = max(0, k - width), min(yg.size, k + width + 1)
    if b - a < 6:
        return None
    return a, b, np.polyfit(grid[a:b] - grid[k], yg[a:b], 2)
