"""Where the backlash ends in the current after a reversal: the rules (settle, fraction against
the median level, against the release line, against the branch just beyond) and the release
branch's features a data sheet reads (swing, slope ratio, shares).

Same grid and indices as :mod:`tsmd.calibration.pieces`; :func:`backlash_end` is the one
:mod:`tsmd.calibration.identify` calls.
"""

from __future__ import annotations

import math

import numpy as np

from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.pieces import flat_runs, slope_per_deg, smooth_crossing, smooth_value
from tsmd.calibration.signal import FloatArray

RELEASE_LOADED_DEG = 0.5
"""Knob travel after the reversal over which the loaded current is averaged (fraction rule)."""
RELEASE_LEVEL_WINDOW_DEG = (5.0, 20.0)
"""Knob travel after the backlash's end over which the release level is the current's median,
as the data sheet defines it (fraction rule)."""
RELEASE_LEVEL_ITERATIONS = 4
RELEASE_SMOOTH_START_DEG = 2.0
""":func:`line_share_end` starts from the first point where the current's mean over this much
travel either side is past the share (one noisy sample is not a crossing)."""
RELEASE_SLOPE_WINDOW_DEG = (5.0, 40.0)
"""Knob travel after the backlash's end over which the release level's slope is read for the
slope ratio (:func:`release_slope_ratio`). Longer than the level's window: a slope read over
15 deg scattered per half-cycle as much as the units differ (ratio sd 0.038, units 0.013), over
35 deg by a quarter of that (0.010) (lumped development units 1-8, session 9). It ends before
the dead-zone edge on the far side (at >= 100 deg of travel on a +-90 deg sweep)."""
EDGE_CLEARANCE_DEG = 3.0
"""The slope window stops this far before a dead-zone edge found in the half-cycle."""
RELEASE_LINE_WINDOW_DEG = (40.0, 95.0)
"""Knob travel after the reversal over which the release branch is fitted as a line
(:func:`release_line`): past the largest backlash of the family (31 deg) and its approach, short
of the far dead-zone edge (>= 100 deg of travel on a +-90 deg sweep; the line also stops
``EDGE_CLEARANCE_DEG`` before an edge found). Fixed relative to the reversal, so the level an
end is tested against does not move with that end. 40-95 deg gave the smallest scatter of B on
the development units of lumped and segments (offline, session 10; 30-70, 35-80, 40-80 tried)."""
RELEASE_LINE_MIN_DEG = 10.0
"""Less fitted travel than this (a short sweep, a near edge): no line, the median level."""


def loaded_current(yg: FloatArray, step_deg: float) -> float:
    """The fraction rule's loaded current: the mean over the first ``RELEASE_LOADED_DEG`` of
    travel after the reversal on the angle grid (the motor's friction has turned by then; the
    one sample at the position's turning point carries it half-turned)."""
    return float(np.mean(yg[:max(1, round(RELEASE_LOADED_DEG / step_deg))]))




def recovered_end(grid: FloatArray, yg: FloatArray, start_k: int, stop: int,
                  level: FloatArray, opts: IdentifyOptions) -> int:
    """Where the current has made up ``backlash_fraction`` of its jump from the loaded current
    at the reversal to the release level.

    The loaded current and the release level are defined as the data sheet measured the
    fraction (:func:`tsmd.datasheet.backlash_settle_fraction`): the current at the reversal
    (mean over its first ``RELEASE_LOADED_DEG``), and the median of the current over
    ``RELEASE_LEVEL_WINDOW_DEG`` of travel after the end found, iterated from the end the first
    flat run's level line gives. A level read off the first few flat degrees is noisy, and a
    fraction of a noisy swing moves the end by degrees where the current approaches its level
    slowly (lumped development units 1-8, noise seeds 0-1, offline: 90.4 -> 94.6 % of values
    within 2 deg, docs/calibration.md). Each step's crossing is read off a quadratic fitted
    around the previous end (:func:`smooth_crossing`), not the first sample that holds above
    the share for ``settle_hold_deg``: that sample scattered by 1 deg (sd) per half-cycle,
    came late on average, and could not come before a noise "peak" late in a release that has
    none (outliers of 5-10 deg). Session 7, same units offline: B's scatter within a grid
    point 1.06 -> 0.3 deg (sd), 94.6 -> 97.7 % of values within 2 deg.
    """
    step = float(grid[1] - grid[0])
    hold = max(2, round(opts.settle_hold_deg / step))
    loaded = loaded_current(yg, step)

    def first_hold(target: FloatArray | float, end: int) -> int | None:
        above = yg[:end] >= target
        stays = np.convolve(above.astype(float), np.ones(hold), mode="valid") >= hold
        hits = np.flatnonzero(stays[start_k:])
        return start_k + int(hits[0]) if hits.size else None

    line_target = np.asarray(loaded + opts.backlash_fraction
                             * (np.polyval(level, grid[:stop]) - loaded), dtype=np.float64)
    k = first_hold(line_target, stop)
    if k is None:
        return stop - 1
    return share_end(grid, yg, k, opts.backlash_fraction, opts.release_fit_half_deg)


def share_end(grid: FloatArray, yg: FloatArray, k: int, share: float, half_deg: float) -> int:
    """From the end ``k``: where the current crosses ``share`` of its swing to the release
    level (median over ``RELEASE_LEVEL_WINDOW_DEG`` after the end), read off the quadratic of
    :func:`smooth_crossing`; the level and the end iterated up to ``RELEASE_LEVEL_ITERATIONS``
    times."""
    step = float(grid[1] - grid[0])
    loaded = loaded_current(yg, step)
    lo_deg, hi_deg = RELEASE_LEVEL_WINDOW_DEG
    for _ in range(RELEASE_LEVEL_ITERATIONS):
        a, b = k + round(lo_deg / step), min(yg.size, k + round(hi_deg / step))
        if b - a < 5:
            break
        target = loaded + share * (float(np.median(yg[a:b])) - loaded)
        k_new = smooth_crossing(grid, yg, k, target, half_deg)
        if k_new == k:
            break
        k = k_new
    return k


def release_line(grid: FloatArray, yg: FloatArray, stop: int | None = None
                 ) -> FloatArray | None:
    """The release branch after a reversal as a line (slope, intercept in ``grid``'s units),
    least squares over ``RELEASE_LINE_WINDOW_DEG`` of travel, ended at ``stop`` (a dead-zone
    edge less its clearance) at the latest; None where less than ``RELEASE_LINE_MIN_DEG`` is left.

    On a catheter whose current keeps climbing after the tip lets go (a release branch sloped by
    0.5-0.8 % of the swing per deg, the segments plant) a level read after each candidate end
    moves with that end, so every point of the branch passes for the share's crossing
    (docs/calibration.md, "a blind plant's backlash"); a line read once does not."""
    x = grid - grid[0]
    last = x[-1] if stop is None else x[max(0, min(stop, x.size) - 1)]
    lo_deg, hi_deg = RELEASE_LINE_WINDOW_DEG
    sel = (x >= lo_deg) & (x <= min(hi_deg, last))
    if np.count_nonzero(sel) * float(grid[1] - grid[0]) < RELEASE_LINE_MIN_DEG:
        return None
    return np.asarray(np.polyfit(grid[sel], yg[sel], 1), dtype=np.float64)


def line_share_end(grid: FloatArray, yg: FloatArray, line: FloatArray, share: float,
                   half_deg: float) -> int:
    """The first point after the reversal where the current has closed ``share`` of its gap
    from the loaded current to the release line at the same knob angle
    (``y = loaded + share x (line - loaded)``), read off the quadratic of
    :func:`smooth_crossing`.

    On a flat branch this is the median level's end; on a sloped one the gap left beyond the
    crossing, (1 - share) x swing, keeps the current above the target, so the crossing is
    single and does not depend on where the search starts."""
    step = float(grid[1] - grid[0])
    loaded = loaded_current(yg, step)
    z = yg - share * np.polyval(line, grid)
    target = (1.0 - share) * loaded
    width = max(1, round(RELEASE_SMOOTH_START_DEG / step))
    mean = np.convolve(z, np.ones(2 * width + 1) / (2 * width + 1), mode="same")
    above = np.flatnonzero(mean[width:z.size - width] >= target)
    if above.size == 0:
        return z.size - 1
    return smooth_crossing(grid, z, width + int(above[0]), target, half_deg)


def line_share_at(grid: FloatArray, yg: FloatArray, k: int, line: FloatArray,
                  half_deg: float) -> float:
    """The share of its gap to the release line that the current has closed at ``k`` (the
    inverse of :func:`line_share_end`; the data sheet reads it at the tip's release)."""
    loaded = loaded_current(yg, float(grid[1] - grid[0]))
    gap = float(np.polyval(line, grid[k])) - loaded
    return math.nan if gap <= 0.0 else (smooth_value(grid, yg, k, half_deg) - loaded) / gap


def local_line(grid: FloatArray, yg: FloatArray, k: int) -> float | None:
    """The release branch just after ``k``: a line fitted over ``RELEASE_LEVEL_WINDOW_DEG``
    past it, read back at ``grid[k]`` (None: the window runs off the half-cycle)."""
    step = float(grid[1] - grid[0])
    a, b = k + round(RELEASE_LEVEL_WINDOW_DEG[0] / step), k + round(
        RELEASE_LEVEL_WINDOW_DEG[1] / step)
    if b > yg.size:
        return None
    return float(np.polyval(np.polyfit(grid[a:b], yg[a:b], 1), grid[k]))


def local_share_at(grid: FloatArray, yg: FloatArray, k: int, half_deg: float) -> float:
    """The share of its gap to :func:`local_line` that the current has closed at ``k`` (the
    data sheet reads it at the tip's release)."""
    loaded = loaded_current(yg, float(grid[1] - grid[0]))
    branch = local_line(grid, yg, k)
    if branch is None or branch <= loaded:
        return math.nan
    return (smooth_value(grid, yg, k, half_deg) - loaded) / (branch - loaded)


def local_share_end(grid: FloatArray, yg: FloatArray, share: float, half_deg: float) -> int:
    """The first point after the reversal where the current (mean over +-2 deg) has closed
    ``share`` of its gap to the branch just beyond it (:func:`local_line`), refined off the
    quadratic of :func:`smooth_crossing`.

    The first such point, not an iteration from a guess: where the current levels off on a
    shelf and only later ramps on (the coilpipe plant: the tip lets go where the shelf begins,
    the ramp to the final level ends 40 deg later) the median level and the 40-95 deg line
    both sit on the ramp's level, and an iteration started on the ramp stays there."""
    step = float(grid[1] - grid[0])
    loaded = loaded_current(yg, step)
    width = max(1, round(RELEASE_SMOOTH_START_DEG / step))
    mean = np.convolve(yg, np.ones(2 * width + 1) / (2 * width + 1), mode="same")
    for k in range(width, yg.size - width):
        branch = local_line(grid, yg, k)
        if branch is None:
            break
        target = loaded + share * (branch - loaded)
        if mean[k] >= target:
            return smooth_crossing(grid, yg, k, target, half_deg)
    return yg.size - 1


def line_end(grid: FloatArray, yg: FloatArray, share: float, opts: IdentifyOptions,
             stop: int | None = None) -> int | None:
    """The end at ``share`` against the release line (:func:`line_share_end`) or the branch
    just beyond (:func:`local_share_end`) where ``opts.release_level`` says so and a line can
    be fitted before ``stop``; else None."""
    if opts.release_level == "local":
        return local_share_end(grid[:stop], yg[:stop], share, opts.release_fit_half_deg)
    if opts.release_level != "line":
        return None
    line = release_line(grid, yg, stop)
    return (None if line is None
            else line_share_end(grid, yg, line, share, opts.release_fit_half_deg))


def fraction_end(grid: FloatArray, yg: FloatArray, k: int, share: float,
                 opts: IdentifyOptions, stop: int | None = None) -> int:
    """The fraction rule's end at ``share``: against the release line (:func:`line_end`),
    else against the median level from the end ``k`` (:func:`share_end`)."""
    end = line_end(grid, yg, share, opts, stop)
    return share_end(grid, yg, k, share, opts.release_fit_half_deg) if end is None else end


def release_swing(grid: FloatArray, yg: FloatArray, k: int) -> float:
    """The current's swing after a reversal: from the loaded current
    (:func:`loaded_current`) to the release level (median over ``RELEASE_LEVEL_WINDOW_DEG``
    after the release end ``k``), NaN where the level cannot be read. Over healthy units of
    both plants the backlash grows with it (session 9), so it tells how much backlash a unit's
    current should show."""
    step = float(grid[1] - grid[0])
    lo_deg, hi_deg = RELEASE_LEVEL_WINDOW_DEG
    a, b = k + round(lo_deg / step), min(yg.size, k + round(hi_deg / step))
    if b - a < 5:
        return math.nan
    return float(np.median(yg[a:b])) - loaded_current(yg, step)


def release_slope_ratio(grid: FloatArray, yg: FloatArray, k: int,
                        stop: int | None = None) -> float:
    """The current's slope over ``RELEASE_SLOPE_WINDOW_DEG`` after the release end ``k`` (the
    tip moving back, the tendon paying out through the sheath's friction) over the loaded
    ramp's slope (the last quarter of the travel: the tip pulled, the tendon drawn in against
    it), NaN where either cannot be read. ``stop``: the window ends there at the latest (a
    dead-zone edge: beyond it the current is the loaded ramp, not the release level).

    Both slopes carry the bending section's stiffness, one divided by the sheath's friction
    factor and one multiplied by it, so their ratio follows the unit's friction-wrap product,
    which is what moves the share of the swing made up at the tip's release from unit to unit
    (docs/calibration.md, sessions 8 and 9)."""
    step = float(grid[1] - grid[0])
    lo_deg, hi_deg = RELEASE_SLOPE_WINDOW_DEG
    b = min(yg.size, k + round(hi_deg / step), yg.size if stop is None else stop)
    a = k + round(lo_deg / step)
    loaded = slope_per_deg(yg[int(0.75 * yg.size):], step)
    if b - a < 5 or not loaded > 0.0:
        return math.nan
    return slope_per_deg(yg[a:b], step) / loaded


def backlash_end(grid: FloatArray, yg: FloatArray, start_k: int,
                  pieces: list[tuple[int, int]], flat: list[bool], noise: float,
                  opts: IdentifyOptions, stop: int | None = None) -> int | None:
    """Where the current becomes constant after the reversal (the paper's point a2).

    While the sheath unloads, the current falls steeply, then less and less steeply as the slip
    front runs distally; when the front reaches the tip the current joins the release level
    (a line, nearly flat). That level is fitted on the first run of flat pieces after the peak
    at least ``min_level_deg`` long; the backlash ends where the current reaches it and stays
    within ``peak_noise_k`` noise sigmas for ``settle_hold_deg``,
    refined to where the current's last ``backlash_tangent_deg`` before that, extended as a line,
    meets the level (the current approaches the level at a slant, so a band alone ends early).
    ``stop``: where the release branch ends at the latest (the dead-zone edge less its
    clearance), for the fraction rule's release line.
    """
    step = float(grid[1] - grid[0])
    min_points = max(3, round(opts.min_level_deg / step))
    # A run that the peak falls inside counts from the peak on (a noise peak at the start of
    # the level must not hide the level).
    runs = [(max(a, start_k), b) for a, b in flat_runs(pieces, flat)]
    run = next(((a, b) for a, b in runs if b - a >= min_points), None)
    if run is None:
        return None
    a0, b0 = run
    level = np.polyfit(grid[a0:b0], yg[a0:b0], 1)
    if opts.backlash == "fraction":
        end = line_end(grid, yg, opts.backlash_fraction, opts, stop)
        return recovered_end(grid, yg, start_k, b0, level, opts) if end is None else end
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
