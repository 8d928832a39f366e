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
  of flat pieces after the peak), see :func:`backlash_end`.

Increasing half-cycles (after the reversal at the negative end) give ``B_neg`` and ``D_pos``;
decreasing ones (after the positive end) give ``B_pos`` and ``D_neg``, as in the paper's model
(``D̂_neg = (H_neg - H_pos)/ω + D_pos - B_pos``: ``B_pos`` is the backlash on the way down).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray
from scipy.signal import find_peaks

from tsmd.calibration.errors import CalibrationError
from tsmd.calibration.health import (
    check_following,
    check_sensor,
    check_signal,
    check_slips,
    find_slip,
)
from tsmd.calibration.knee import resolvable_end
from tsmd.calibration.options import LINE_SHARE_UNIT_U95, IdentifyOptions
from tsmd.calibration.pieces import (
    constant_phase,
    fitted_edge,
    flat_pieces,
    knee_edge,
    linear_pieces,
)
from tsmd.calibration.recovery import recovery_end
from tsmd.calibration.release import (
    EDGE_CLEARANCE_DEG,
    backlash_end,
    fraction_end,
    release_slope_ratio,
    release_swing,
)
from tsmd.calibration.signal import Conditioned, FloatArray, condition
from tsmd.calibration.slack_rise import before_sustained_rise
from tsmd.calibration.stick_end import stick_end_index
from tsmd.calibration.sweep_result import PARAMETERS, HalfCycle, SweepResult

SHARE_STEP = 0.01
"""Half the share interval over which a release end's travel per unit of share is read (the
end at the share -+ this much): wide enough that the current's noise moves the two ends
little, narrow against the share's own range (0.90-0.97 on segments)."""


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


def resample_on_angle(x: FloatArray, y: FloatArray, direction: int,
                       step_deg: float) -> tuple[FloatArray, FloatArray]:
    """y on a uniform grid of the direction-signed angle ``direction * x`` (made monotonic)."""
    s = np.maximum.accumulate(direction * x)
    grid = np.arange(s[0], s[-1], step_deg)
    if grid.size < 2:
        return grid, np.interp(grid, s, y)
    # np.interp needs increasing abscissae: flat stretches keep their last value.
    keep = np.concatenate([np.diff(s) > 0, [True]])
    return grid, np.interp(grid, s[keep], y[keep])


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

    grid, yg = resample_on_angle(pos, y, direction, step)
    min_size = max(2, round(2.0 / step))
    if grid.size < 3 * min_size:
        return HalfCycle(direction, start, stop, after_reversal,
                         problems=(f"{where}: only {span:.1f} deg of travel",))
    # The last degrees before the next reversal belong to the motor's deceleration: left out.
    end = max(3 * min_size, yg.size - round(opts.edge_margin_deg / step))
    pieces = linear_pieces(yg[:end], noise, opts)
    flat = flat_pieces(yg[:end], step, pieces, opts)
    current = data.current_filtered_A
    loaded_swing = 0.5 * float(np.nanmax(current) - np.nanmin(current))
    plateau_run = (None if flat is None
                   else constant_phase(pieces, flat, step, opts, yg[:end], loaded_swing))
    if plateau_run is not None and flat is not None:
        plateau_run = before_sustained_rise(pieces, flat, step, opts, yg[:end], plateau_run)
    if plateau_run is None:
        plateau_run = (0, end)
        problems.append(f"{where}: no stretch of constant current")

    peak: int | None = None
    visibility = math.nan
    settle = 0
    backlash_deg = math.nan
    swing = math.nan
    if after_reversal:
        # The small peak after the reversal (find_peaks); it belongs to the transient before the
        # constant phase (noise on the plateau has peaks too).
        hold = max(2, round(opts.settle_hold_deg / step))
        transient = yg[:min(plateau_run[0] + hold + 1, plateau_run[1])]
        peaks, _ = find_peaks(transient, prominence=opts.peak_noise_k * noise)
        peak = int(peaks[0]) if peaks.size else None
        start_k = peak if peak is not None else 0
        branch_stop = (plateau_run[1] - round(EDGE_CLEARANCE_DEG / step)
                       if plateau_run[1] < end else None)
        if opts.backlash == "recovery":
            recovery = recovery_end(grid[:end], yg[:end], noise, branch_stop)
            found = None if recovery is None else recovery.end
            visibility = math.nan if recovery is None else recovery.visibility
        else:
            found = (None if flat is None
                     else backlash_end(grid[:end], yg[:end], start_k, pieces, flat, noise, opts,
                                       branch_stop))
        if found is not None and opts.backlash == "fraction" and opts.backlash_knee:
            found = resolvable_end(grid[:end], yg[:end], found, branch_stop)
        stick = stick_end_index(grid[:end], yg[:end]) if opts.backlash_stick_end else None
        found = found if stick is None else stick
        if found is None:
            # No value rather than a guess: the quality checks then name this reason.
            problems.append(f"{where}: the current never becomes constant after the reversal")
        else:
            settle = found
            # The backlash counts from the reversal (the model's X_ref); by the settle rule
            # it ends where the data sheet's unit let go after its current settled.
            lag_deg = 0.0 if stick is not None else {
                "settle": opts.backlash_settle_lag_deg,
                "recovery": opts.backlash_recovery_lag_deg}.get(opts.backlash, 0.0)
            lagged = min(max(settle + round(lag_deg / step), 0), end - 1)
            backlash_deg = float(grid[lagged] - grid[0])
            swing = release_swing(grid[:end], yg[:end], settle)

    # The dead-zone edge: where the constant-current stretch ends and the current rises.
    edge_k: int | None = plateau_run[1] if plateau_run[1] < end else None
    if edge_k is not None and opts.edge == "knee":
        edge_k = knee_edge(yg[:end], step, pieces, edge_k, opts)
    elif edge_k is not None and opts.edge == "fit":
        edge_k = fitted_edge(grid[:end], yg[:end], plateau_run[0], edge_k, noise, opts)
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
        return None if k is None else _index_at(pos, direction, grid, k, start)

    return HalfCycle(
        direction=direction, start=start, stop=stop, after_reversal=after_reversal,
        peak_index=index_at(peak),
        backlash_end_index=index_at(round(backlash_deg / step))
        if after_reversal and math.isfinite(backlash_deg) else None,
        edge_index=index_at(edge_k) if math.isfinite(edge_deg) else None,
        backlash_deg=backlash_deg, edge_deg=edge_deg, plateau_A=direction * plateau,
        rise_A=rise, snr=snr, problems=tuple(problems), slip=slip, release_swing_A=swing,
        backlash_visibility=visibility)


def _index_at(pos: FloatArray, direction: int, grid: FloatArray, k: int, start: int) -> int:
    """The sample (into the sweep's arrays) where the knob reaches the grid's angle ``k``."""
    target = direction * grid[min(k, grid.size - 1)]
    hits = np.flatnonzero(direction * (pos - target) >= 0)
    return start + int(hits[0]) if hits.size else start + pos.size - 1


def unit_share_backlash(data: Conditioned, halves: tuple[HalfCycle, ...],
                        opts: IdentifyOptions) -> tuple[HalfCycle, ...]:
    """The fraction rule's release ends moved to this unit's own share of the swing.

    The share at which the tip lets go differs from unit to unit (lumped development units:
    0.939-0.971 against one sheet's 0.957), and so does the release-to-loaded slope ratio that
    follows the sheath's friction-wrap product; the sweep's mean ratio (one half-cycle's is
    too noisy) moves the sheet's share by ``backlash_share_per_slope_ratio`` per unit of ratio
    away from the sheet unit's. Without a reference ratio (or with the
    stick end, :mod:`tsmd.calibration.stick_end`, which takes no share) the halves are returned
    as they are.
    """
    ref = opts.backlash_reference_slope_ratio
    if opts.backlash != "fraction" or ref is None or opts.backlash_stick_end:
        return halves
    step = opts.grid_step_deg
    curves: dict[int, tuple[FloatArray, FloatArray, FloatArray, int]] = {}
    stops: list[int | None] = []
    for i, h in enumerate(halves):
        if h.after_reversal and math.isfinite(h.backlash_deg):
            pos = data.pos_deg[h.start:h.stop]
            grid, yg = resample_on_angle(
                pos, h.direction * data.current_filtered_A[h.start:h.stop], h.direction, step)
            end = yg.size - round(opts.edge_margin_deg / step)
            curves[i] = (pos, grid[:end], yg[:end], round(h.backlash_deg / step))
            stops.append(None if not math.isfinite(h.edge_deg) else int(
                np.searchsorted(grid, h.direction * h.edge_deg)) - round(EDGE_CLEARANCE_DEG / step))
    ratios = [release_slope_ratio(g, y, k, stop)
              for (_, g, y, k), stop in zip(curves.values(), stops, strict=True)]
    finite = [r for r in ratios if math.isfinite(r)]
    if not finite:
        return halves
    share = opts.backlash_fraction + opts.backlash_share_per_slope_ratio * (
        float(np.mean(finite)) - ref)
    share = min(max(share, 0.5), 0.999)
    out = list(halves)
    for j, (i, (pos, grid, yg, k)) in enumerate(curves.items()):
        k_new = fraction_end(grid, yg, min(k, yg.size - 1), share, opts, stops[j])
        if opts.backlash_knee:
            k_new = resolvable_end(grid, yg, k_new, stops[j])
        h = halves[i]
        out[i] = replace(h, backlash_deg=float(grid[k_new] - grid[0]),
                         backlash_end_index=_index_at(pos, h.direction, grid, k_new, h.start),
                         release_swing_A=release_swing(grid, yg, k_new),
                         share_u95_deg=(_share_u95_deg(grid, yg, k, share, opts, stops[j])
                                        if opts.release_level == "line" else math.nan))
    return tuple(out)


def _share_u95_deg(grid: FloatArray, yg: FloatArray, k: int, share: float,
                   opts: IdentifyOptions, stop: int | None) -> float:
    """The 95 % half-width of one release end that the share's unit part gives: the knob
    travel between the ends at ``share`` -+ ``SHARE_STEP``, per unit of share, times
    ``LINE_SHARE_UNIT_U95`` (a slow approach to the release line: a wide B)."""
    ends = [fraction_end(grid, yg, min(k, yg.size - 1), share + d, opts, stop)
            for d in (-SHARE_STEP, SHARE_STEP)]
    travel_per_share = abs(float(grid[ends[1]] - grid[ends[0]])) / (2.0 * SHARE_STEP)
    return LINE_SHARE_UNIT_U95 * travel_per_share


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
    halves = unit_share_backlash(
        data, tuple(analyse_half_cycle(data, d, a, b, r, opts) for d, a, b, r in stretches), opts)
    check_signal(data, [(h.direction, h.start, h.stop, h.snr) for h in halves], opts.min_snr)
    check_slips([h.slip for h in halves if h.snr >= opts.min_snr])
    values: dict[str, list[float]] = {name: [] for name in PARAMETERS}
    for h in halves:
        seen = not h.backlash_visibility < opts.min_backlash_visibility  # NaN: other rules
        if math.isfinite(h.backlash_deg) and seen:
            values[h.backlash_name].append(h.backlash_deg)
        if math.isfinite(h.edge_deg):
            values[h.edge_name].append(h.edge_deg)
    return SweepResult(data, halves, {k: tuple(v) for k, v in values.items()})


def settle_rule_backlash(data: Conditioned, options: IdentifyOptions | None = None
                         ) -> tuple[float, float]:
    """(B_pos, B_neg) of a conditioned sweep by the paper's settle rule, median over the
    half-cycles after a reversal, whatever rule the product's calibration uses for the paper's B.

    The tension play's straight release line starts where the release has settled: a
    fraction rule's earlier end (where the tip starts to move, on a Dahl-friction catheter)
    gives its backlash gain the curved start of the release, not its slope.
    """
    opts = replace(options or IdentifyOptions(), backlash="settle", backlash_settle_lag_deg=0.0)
    values: dict[str, list[float]] = {"backlash_pos_deg": [], "backlash_neg_deg": []}
    for d, a, b, after in split_half_cycles(data.cmd_deg, opts.min_reversal_deg):
        if not after:
            continue
        h = analyse_half_cycle(data, d, a, b, True, opts)
        if math.isfinite(h.backlash_deg):
            values[h.backlash_name].append(h.backlash_deg)
    pos, neg = values["backlash_pos_deg"], values["backlash_neg_deg"]
    return (float(np.median(pos)) if pos else math.nan,
            float(np.median(neg)) if neg else math.nan)
