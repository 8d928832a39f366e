"""Dead zone and backlash of one knob from one sweep, using motor position and current only.

The paper's identification (section "Parameter Identification"): after each reversal the current
jumps, makes a small peak and settles to a constant level while the tendon slack is taken up
(backlash, ``B``); it stays constant through the dead zone and starts to rise (or fall) where the
tendon loads the tip again (dead-zone edge, ``D``). Here, per monotonic half-cycle:

* the current against knob angle is cut into linear pieces by :mod:`ruptures` (PELT,
  continuous piecewise-linear cost); the last long run of flat pieces is the constant phase;
* the dead-zone edge: where that run ends and the current starts to rise (the paper's), or,
  with ``edge="knee"``, where the steep first rise turns into the loaded ramp;
* the peak after the reversal: :func:`scipy.signal.find_peaks` on the direction-signed current;
  the backlash ends where the current then joins the constant level that follows (the first run
  of flat pieces after the peak), see :func:`_backlash_end`.

Increasing half-cycles (after the reversal at the negative end) give ``B_neg`` and ``D_pos``;
decreasing ones (after the positive end) give ``B_pos`` and ``D_neg``, as in the paper's model
(``D̂_neg = (H_neg - H_pos)/ω + D_pos - B_pos``: ``B_pos`` is the backlash on the way down).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import ruptures as rpt
from numpy.typing import NDArray
from scipy.signal import find_peaks

from tsmd.calibration.branch_fit import fit_edge
from tsmd.calibration.errors import CalibrationError
from tsmd.calibration.health import (
    check_following,
    check_sensor,
    check_signal,
    check_slips,
    find_slip,
)
from tsmd.calibration.signal import Conditioned, FloatArray, condition

PARAMETERS: tuple[str, ...] = (
    "dead_zone_pos_deg", "dead_zone_neg_deg", "backlash_pos_deg", "backlash_neg_deg")
SHORT = {"dead_zone_pos_deg": "D_pos", "dead_zone_neg_deg": "D_neg",
         "backlash_pos_deg": "B_pos", "backlash_neg_deg": "B_neg"}


@dataclass(frozen=True)
class IdentifyOptions:
    """Tuning of the identification; the defaults follow the paper where it says something."""

    cutoff_hz: float = 20.0
    filter_order: int = 3
    max_gap_s: float = 0.5
    min_reversal_deg: float = 10.0
    """Direction changes smaller than this are jitter, not reversals."""
    grid_step_deg: float = 0.25
    """The current is resampled on this knob-angle grid for change-point detection."""
    min_snr: float = 4.0
    """The current must rise by this many noise sigmas past the dead-zone edge."""
    edge_margin_deg: float = 3.0
    """An edge closer than this to the end of a half-cycle was not reached."""
    peak_noise_k: float = 3.0
    """A peak after a reversal must stand out of the noise by this many sigmas."""
    flat_slope_fraction: float = 0.3
    """"Constant" current: rising slower than this fraction of the loaded ramp's slope."""
    penalty_k: float = 20.0
    """Change-point penalty in units of noise variance x log(n) (PELT)."""
    edge: str = "fit"
    """"fit" (the default): the least-squares line intersection of the dead-zone level with the
    loaded ramp, or with the end of a steep first rise where the current shows one
    (:mod:`tsmd.calibration.branch_fit`); "knee": the same from the change points' pieces;
    "rise": the paper's edge, where the current starts to rise (the tendon engages; the tip
    follows a few degrees later, and the exact start of a gentle rise scatters by 3 deg from
    cycle to cycle; docs/calibration.md)."""
    knee_slope_ratio: float = 1.5
    fit_before_deg: float = 12.0
    """``edge="fit"``: the window fitted starts this far before the rise the pieces show ..."""
    fit_after_deg: float = 15.0
    """... and ends this far after it (the loaded ramp)."""
    max_knee_deg: float = 15.0
    settle_hold_deg: float = 1.0
    """The current must stay on the constant level this long to count as settled."""
    backlash_tangent_deg: float = 3.0
    """Stretch of current before it settles that is extended to meet the constant level."""
    backlash: str = "settle"
    """"settle" (the paper's point a2): where the current joins the release level within the
    noise; "fraction": where it has made up ``backlash_fraction`` of its jump to that level."""
    backlash_fraction: float = 0.975
    min_level_deg: float = 3.0
    """A run of flat pieces shorter than this after a reversal is a pause in the transient (a
    turn of the filtered reversal, a speed change), not the release level, which lasts until
    the dead-zone edge."""
    max_tracking_error_deg: float = 10.0
    min_follow_ratio: float = 0.5
    """The knob must travel at least this fraction of the commanded travel (else: stalled)."""


@dataclass(frozen=True)
class HalfCycle:
    """One monotonic stretch between reversals and what was found in it (indices into arrays)."""

    direction: int
    start: int
    stop: int
    after_reversal: bool
    peak_index: int | None = None
    backlash_end_index: int | None = None
    edge_index: int | None = None
    backlash_deg: float = math.nan
    edge_deg: float = math.nan
    plateau_A: float = math.nan
    rise_A: float = math.nan
    snr: float = math.nan
    problems: tuple[str, ...] = ()
    slip: str | None = None
    """Where the loaded current dropped while the knob moved on, if it did."""

    @property
    def backlash_name(self) -> str:
        return "backlash_neg_deg" if self.direction > 0 else "backlash_pos_deg"

    @property
    def edge_name(self) -> str:
        return "dead_zone_pos_deg" if self.direction > 0 else "dead_zone_neg_deg"


@dataclass(frozen=True)
class SweepResult:
    """Everything one sweep gave: conditioned signals, half-cycles, values per parameter."""

    data: Conditioned
    half_cycles: tuple[HalfCycle, ...]
    values: dict[str, tuple[float, ...]] = field(default_factory=dict)
    """Each parameter's value from every half-cycle that gave one, in time order."""
    resweeps: int = 0
    """How many re-sweeps were pooled into this result."""

    def estimate(self, name: str) -> float:
        """Median over the half-cycles (NaN when none gave a value)."""
        v = self.values.get(name, ())
        return float(np.median(v)) if v else math.nan

    def spread(self, name: str) -> float:
        """Largest minus smallest value over the half-cycles (0 with one value)."""
        v = self.values.get(name, ())
        return float(np.ptp(v)) if v else math.nan

    def merged(self, other: SweepResult) -> SweepResult:
        """This sweep's half-cycles pooled with a re-sweep's (the first sweep's signals kept)."""
        values = {name: self.values.get(name, ()) + other.values.get(name, ())
                  for name in PARAMETERS}
        return SweepResult(self.data, self.half_cycles + other.half_cycles, values,
                           self.resweeps + 1)

    @property
    def snr(self) -> float:
        values = [h.snr for h in self.half_cycles if math.isfinite(h.snr)]
        return float(min(values)) if values else math.nan

    @property
    def median_snr(self) -> float:
        """The typical half-cycle's signal (one weak half-cycle gives no value, not a verdict)."""
        values = [h.snr for h in self.half_cycles if math.isfinite(h.snr)]
        return float(np.median(values)) if values else math.nan

    @property
    def problems(self) -> tuple[str, ...]:
        return tuple(p for h in self.half_cycles for p in h.problems)


def find_reversals(cmd_deg: FloatArray, min_reversal_deg: float) -> list[int]:
    """Indices where the commanded position turns by more than ``min_reversal_deg`` (zigzag)."""
    reversals: list[int] = []
    direction = 0
    extreme = 0
    for i in range(1, cmd_deg.size):
        x = cmd_deg[i]
        if direction == 0:
            if abs(x - cmd_deg[0]) > min_reversal_deg:
                direction = 1 if x > cmd_deg[0] else -1
                extreme = i
        elif direction * (x - cmd_deg[extreme]) >= 0:
            extreme = i
        elif direction * (cmd_deg[extreme] - x) > min_reversal_deg:
            reversals.append(extreme)
            direction, extreme = -direction, i
    return reversals


def _moving_start(cmd_deg: FloatArray) -> int:
    """First index where the command has left its starting value (skips a still lead-in)."""
    moved = np.flatnonzero(np.abs(np.diff(cmd_deg)) > 1e-9)
    return int(moved[0]) if moved.size else 0


def split_half_cycles(cmd_deg: FloatArray,
                      min_reversal_deg: float) -> list[tuple[int, int, int, bool]]:
    """(direction, start, stop, after_reversal) for each monotonic stretch of the command."""
    reversals = find_reversals(cmd_deg, min_reversal_deg)
    bounds = [_moving_start(cmd_deg), *reversals, cmd_deg.size - 1]
    out = []
    for k in range(len(bounds) - 1):
        a, b = bounds[k], bounds[k + 1]
        travel = cmd_deg[b] - cmd_deg[a]
        if abs(travel) < min_reversal_deg:
            continue
        out.append((1 if travel > 0 else -1, a, b + 1, k > 0))
    return out


def _resample_on_angle(x: FloatArray, y: FloatArray, direction: int,
                       step_deg: float) -> tuple[FloatArray, FloatArray]:
    """y on a uniform grid of the direction-signed angle ``direction * x`` (made monotonic)."""
    s = np.maximum.accumulate(direction * x)
    grid = np.arange(s[0], s[-1], step_deg)
    if grid.size < 2:
        return grid, np.interp(grid, s, y)
    # np.interp needs increasing abscissae: flat stretches keep their last value.
    keep = np.concatenate([np.diff(s) > 0, [True]])
    return grid, np.interp(grid, s[keep], y[keep])


def _change_points(y: FloatArray, n_bkps: int, min_size: int) -> list[int]:
    """Breakpoints of a continuous piecewise-linear fit (ruptures, exact dynamic programming)."""
    if y.size < (n_bkps + 1) * min_size:
        return []
    algo = rpt.Dynp(model="clinear", min_size=min_size, jump=max(1, y.size // 200)).fit(y)
    return [int(b) for b in algo.predict(n_bkps=n_bkps)[:-1]]


def _slope(y: FloatArray, step: float) -> float:
    if y.size < 2:
        return 0.0
    return float(np.polyfit(np.arange(y.size) * step, y, 1)[0])


def _pieces(yg: FloatArray, noise: float, opts: IdentifyOptions) -> list[tuple[int, int]]:
    """Linear pieces of the current against angle (ruptures PELT, continuous linear cost)."""
    penalty = max(opts.penalty_k * noise ** 2 * math.log(max(yg.size, 2)), 1e-15)
    jump = max(2, yg.size // 400)
    algo = rpt.Pelt(model="clinear", min_size=2, jump=jump).fit(yg)
    bkps = [int(b) for b in algo.predict(pen=penalty)]
    return list(zip([0, *bkps[:-1]], bkps, strict=True))


def _flat_pieces(yg: FloatArray, step: float, pieces: list[tuple[int, int]],
                 opts: IdentifyOptions) -> list[bool] | None:
    """Which pieces are flat: rising slower than ``flat_slope_fraction`` of the loaded ramp
    (the slope over the last quarter of the travel), or falling gently (a fall as steep as the
    ramp is the peak after a reversal coming down, not a plateau). None without a ramp."""
    loaded = _slope(yg[int(0.75 * yg.size):], step)
    if loaded <= 0:
        return None
    slopes = [_slope(yg[a:b], step) for a, b in pieces]
    return [-loaded < s < opts.flat_slope_fraction * loaded for s in slopes]


def _plateau(pieces: list[tuple[int, int]], flat: list[bool], step: float,
             opts: IdentifyOptions) -> tuple[int, int] | None:
    """The constant-current stretch before the dead-zone edge (start, stop on the grid): the last
    run of flat pieces at least ``min_level_deg`` long (else the longest run).

    Not simply the longest: the release level after a reversal is flat too, and where the tip
    re-enters the dead zone the released tendon drops its last tension, a short step that cuts
    the two apart; the release run can then be the longer one (fast sweeps, phi2 at +90 deg).
    """
    runs = _flat_runs(pieces, flat)
    long_enough = [r for r in runs if (r[1] - r[0]) * step >= opts.min_level_deg]
    if long_enough:
        return long_enough[-1]
    return max(runs, key=lambda r: r[1] - r[0], default=None)


def _flat_runs(pieces: list[tuple[int, int]], flat: list[bool]) -> list[tuple[int, int]]:
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


def _knee(yg: FloatArray, step: float, pieces: list[tuple[int, int]], rise_k: int,
          opts: IdentifyOptions) -> int:
    """Beyond the paper: where the steep first rise (the tendon stretching while the tip is
    still held) turns into the loaded ramp (the tip moving). No steep part: the rise itself."""
    loaded = _slope(yg[int(0.75 * yg.size):], step)
    limit = rise_k + int(opts.max_knee_deg / step)
    steep = False
    for a, b in pieces:
        if b <= rise_k:
            continue
        if a >= limit:
            break
        slope = _slope(yg[max(a, rise_k):b], step)
        if slope > opts.knee_slope_ratio * loaded:
            steep = True
        elif steep:
            return max(a, rise_k)
    return rise_k


def _fitted_edge(grid: FloatArray, yg: FloatArray, plateau_start: int, rise_k: int,
                 noise: float, opts: IdentifyOptions) -> int:
    """The edge as the least-squares line intersection around the rise the pieces show
    (:func:`tsmd.calibration.branch_fit.fit_edge`); the rise itself when nothing fits."""
    step = float(grid[1] - grid[0])
    a = max(plateau_start, rise_k - round(opts.fit_before_deg / step))
    b = min(yg.size, rise_k + round(opts.fit_after_deg / step))
    fit = fit_edge(grid[a:b], yg[a:b], noise, knee_slope_ratio=opts.knee_slope_ratio,
                   max_knee_deg=opts.max_knee_deg, penalty_k=opts.penalty_k,
                   search_step_deg=step)
    if fit is None:
        return rise_k
    return min(int(np.searchsorted(grid, fit.edge_deg)), yg.size - 1)


def _recovered(grid: FloatArray, yg: FloatArray, start_k: int, stop: int,
               level: FloatArray, opts: IdentifyOptions) -> int:
    """Where the current has made up ``backlash_fraction`` of its jump from the loaded current
    before the reversal to the release level, and stays there for ``settle_hold_deg``."""
    step = float(grid[1] - grid[0])
    loaded = float(np.min(yg[:max(stop, 2)]))
    target = loaded + opts.backlash_fraction * (np.polyval(level, grid[:stop]) - loaded)
    above = yg[:stop] >= target
    hold = max(2, round(opts.settle_hold_deg / step))
    stays = np.convolve(above.astype(float), np.ones(hold), mode="valid") >= hold
    hits = np.flatnonzero(stays[start_k:])
    return start_k + int(hits[0]) if hits.size else stop - 1


def _backlash_end(grid: FloatArray, yg: FloatArray, start_k: int,
                  pieces: list[tuple[int, int]], flat: list[bool], noise: float,
                  opts: IdentifyOptions) -> int | None:
    """Where the current becomes constant after the reversal (the paper's point a2).

    While the sheath unloads, the current falls steeply, then less and less steeply as the slip
    front runs distally; when the front reaches the tip the current joins the release level
    (a line, nearly flat). That level is fitted on the first run of flat pieces after the peak
    at least ``min_level_deg`` long; the backlash ends where the current reaches it and stays
    within ``peak_noise_k`` noise sigmas for ``settle_hold_deg``,
    refined to where the current's last ``backlash_tangent_deg`` before that, extended as a line,
    meets the level (the current approaches the level at a slant, so a band alone ends early).
    """
    step = float(grid[1] - grid[0])
    min_points = max(3, round(opts.min_level_deg / step))
    # A run that the peak falls inside counts from the peak on (a noise peak at the start of
    # the level must not hide the level).
    runs = [(max(a, start_k), b) for a, b in _flat_runs(pieces, flat)]
    run = next(((a, b) for a, b in runs if b - a >= min_points), None)
    if run is None:
        return None
    a0, b0 = run
    level = np.polyfit(grid[a0:b0], yg[a0:b0], 1)
    if opts.backlash == "fraction":
        return _recovered(grid, yg, start_k, b0, level, opts)
    near = np.abs(yg[start_k:b0] - np.polyval(level, grid[start_k:b0])) <= opts.peak_noise_k * noise
    hold = max(2, round(opts.settle_hold_deg / step))
    stays = np.convolve(near.astype(float), np.ones(hold), mode="valid") >= hold
    hits = np.flatnonzero(stays)
    settle = start_k + int(hits[0]) if hits.size else a0
    width = round(opts.backlash_tangent_deg / step)
    lo = max(start_k, settle - width)
    if settle - lo >= 3:
        tangent = np.polyfit(grid[lo:settle], yg[lo:settle], 1)
        if abs(tangent[0] - level[0]) > 1e-12:
            x = (level[1] - tangent[1]) / (tangent[0] - level[0])
            k = int(np.searchsorted(grid, x))
            if settle <= k <= settle + width:
                settle = k
    return settle


def analyse_half_cycle(data: Conditioned, direction: int, start: int, stop: int,
                       after_reversal: bool, opts: IdentifyOptions) -> HalfCycle:
    """Peak, backlash end and dead-zone edge in one monotonic stretch."""
    pos = data.pos_deg[start:stop]
    y = direction * data.current_filtered_A[start:stop]
    problems: list[str] = []
    sign = "+" if direction > 0 else "-"
    where = f"{sign} half-cycle at t={data.t_s[start]:.1f}-{data.t_s[stop - 1]:.1f} s"
    span = abs(pos[-1] - pos[0])
    step = opts.grid_step_deg
    noise = max(data.filtered_noise_A, 1e-12)

    grid, yg = _resample_on_angle(pos, y, direction, step)
    min_size = max(2, round(2.0 / step))
    if grid.size < 3 * min_size:
        return HalfCycle(direction, start, stop, after_reversal,
                         problems=(f"{where}: only {span:.1f} deg of travel",))
    # The last degrees before the next reversal belong to the motor's deceleration: left out.
    end = max(3 * min_size, yg.size - round(opts.edge_margin_deg / step))
    pieces = _pieces(yg[:end], noise, opts)
    flat = _flat_pieces(yg[:end], step, pieces, opts)
    plateau_run = None if flat is None else _plateau(pieces, flat, step, opts)
    if plateau_run is None:
        plateau_run = (0, end)
        problems.append(f"{where}: no stretch of constant current")

    peak: int | None = None
    settle = 0
    backlash_deg = math.nan
    if after_reversal:
        # The small peak after the reversal (find_peaks); it belongs to the transient before the
        # constant phase (noise on the plateau has peaks too).
        hold = max(2, round(opts.settle_hold_deg / step))
        transient = yg[:min(plateau_run[0] + hold + 1, plateau_run[1])]
        peaks, _ = find_peaks(transient, prominence=opts.peak_noise_k * noise)
        peak = int(peaks[0]) if peaks.size else None
        start_k = peak if peak is not None else 0
        found = (None if flat is None
                 else _backlash_end(grid[:end], yg[:end], start_k, pieces, flat, noise, opts))
        if found is None:
            # No value rather than a guess: the quality checks then name this reason.
            problems.append(f"{where}: the current never becomes constant after the reversal")
        else:
            settle = found
            # The backlash counts from the reversal (the model's X_ref).
            backlash_deg = float(grid[settle] - grid[0])

    # The dead-zone edge: where the constant-current stretch ends and the current rises.
    edge_k: int | None = plateau_run[1] if plateau_run[1] < end else None
    if edge_k is not None and opts.edge == "knee":
        edge_k = _knee(yg[:end], step, pieces, edge_k, opts)
    elif edge_k is not None and opts.edge == "fit":
        edge_k = _fitted_edge(grid[:end], yg[:end], plateau_run[0], edge_k, noise, opts)
    plateau = float(np.median(yg[plateau_run[0]:plateau_run[1]]))
    rise = float(np.median(yg[max(end - min_size, plateau_run[0]):end]) - plateau)
    snr = rise / noise
    edge_deg = math.nan
    slip: str | None = None
    if snr < opts.min_snr:
        problems.append(
            f"{where}: no current rise out of the dead zone (rise {rise * 1e3:.1f} mA = "
            f"{snr:.1f} x noise < {opts.min_snr:g}); the sweep may never leave the dead zone")
    elif edge_k is None or (grid[end - 1] - grid[edge_k]) < opts.edge_margin_deg:
        problems.append(f"{where}: the current rises only at the end of the travel; "
                        "the dead-zone edge was not reached")
    else:
        edge_deg = float(direction * grid[edge_k])
    if snr >= opts.min_snr:
        # From where the release has settled on: a slipping knob may hide the edge itself.
        dropped = find_slip(grid[:end], yg[:end], max(plateau_run[0], settle), noise)
        slip = f"{where}: {dropped}" if dropped else None

    def index_at(k: int | None) -> int | None:
        if k is None:
            return None
        target = direction * grid[min(k, grid.size - 1)]
        hits = np.flatnonzero(direction * (pos - target) >= 0)
        return start + int(hits[0]) if hits.size else stop - 1

    return HalfCycle(
        direction=direction, start=start, stop=stop, after_reversal=after_reversal,
        peak_index=index_at(peak),
        backlash_end_index=index_at(settle) if after_reversal and math.isfinite(backlash_deg)
        else None,
        edge_index=index_at(edge_k) if math.isfinite(edge_deg) else None,
        backlash_deg=backlash_deg, edge_deg=edge_deg, plateau_A=direction * plateau,
        rise_A=rise, snr=snr, problems=tuple(problems), slip=slip)


def identify_sweep(t_s: NDArray[np.floating], cmd_deg: NDArray[np.floating],
                   pos_deg: NDArray[np.floating], current_A: NDArray[np.floating],
                   options: IdentifyOptions | None = None,
                   sweep_start_s: float | None = None) -> SweepResult:
    """Identify D and B of the swept knob from its position and current (never the tip).

    With ``sweep_start_s``, only the half-cycles from the reversal at the sweep's start on are
    used (the moves that bring the knobs there are not part of the sweep); without it, every
    half-cycle is, and the first one (not after a reversal) gives only a dead-zone edge.
    """
    opts = options or IdentifyOptions()
    raw = np.asarray(current_A, float)
    data = condition(np.asarray(t_s, float), np.asarray(cmd_deg, float),
                     np.asarray(pos_deg, float), raw,
                     cutoff_hz=opts.cutoff_hz, order=opts.filter_order,
                     max_gap_s=opts.max_gap_s)
    if np.isfinite(raw).any() and np.nanmax(raw) == np.nanmin(raw):
        raise CalibrationError("the current is constant: no current feedback from the drive")
    # On the raw readings: spike removal and the low-pass would hide a stuck or clipped sensor.
    check_sensor(np.asarray(t_s, float), np.asarray(pos_deg, float), raw)
    check_following(data, opts.min_reversal_deg, opts.min_follow_ratio,
                    opts.max_tracking_error_deg)
    stretches = split_half_cycles(data.cmd_deg, opts.min_reversal_deg)
    if sweep_start_s is not None:
        # The protocol brings the knob to -A going down: the sweep's first stretch follows a
        # reversal even when the way down is not in this recording.
        first = int(np.searchsorted(data.t_s, sweep_start_s)) - 2
        first = max(first, 0)
        stretches = [(d, max(a, first), b, True) for d, a, b, _ in stretches if b > first + 1]
    if not stretches:
        raise CalibrationError(
            f"the command never moves more than {opts.min_reversal_deg:g} deg: nothing to identify")
    halves = tuple(analyse_half_cycle(data, d, a, b, r, opts) for d, a, b, r in stretches)
    check_signal(data, [(h.direction, h.start, h.stop, h.snr) for h in halves], opts.min_snr)
    check_slips([h.slip for h in halves if h.snr >= opts.min_snr])
    values: dict[str, list[float]] = {name: [] for name in PARAMETERS}
    for h in halves:
        if math.isfinite(h.backlash_deg):
            values[h.backlash_name].append(h.backlash_deg)
        if math.isfinite(h.edge_deg):
            values[h.edge_name].append(h.edge_deg)
    return SweepResult(data, halves, {k: tuple(v) for k, v in values.items()})
