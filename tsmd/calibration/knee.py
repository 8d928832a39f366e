"""Where the current after a reversal still says where the backlash ends: its knee.

Every fraction rule (:mod:`tsmd.calibration.release`) ends the backlash where the current has
closed a share of its way to a release level. Past the knee, where the current's approach slows
to the release branch's own creep, the crossing is a matter of noise: on the stickslip plant the
current creeps 0.1 % of its swing per deg with 0.5-0.9 % of scatter that averaging does not
remove, so 1 % of level error moves a share's crossing by 10 deg (docs/calibration.md, session
11 lead and session 12). So a crossing is only trusted where the current's rise over the creep,
per degree, is larger than its scatter per ``KNEE_TOLERANCE_DEG``; a crossing beyond the first
point where that fails is replaced by that point (the knee), where the current still moves.
"""

from __future__ import annotations

import numpy as np

from tsmd.calibration.release import RELEASE_LINE_WINDOW_DEG, release_line
from tsmd.calibration.signal import FloatArray, robust_sigma

KNEE_TOLERANCE_DEG = 1.0
"""How far the scatter may move a crossing: half the 2 deg the backlash is scored against."""
KNEE_SLOPE_HALF_DEG = 2.0
"""The current's slope is read by least squares over this much travel either side; its mean
over the same width is what the scatter is measured on."""
KNEE_TREND_HALF_DEG = 8.0
"""The scatter is that mean's deviation from the mean over this much travel either side (a
trend slower than that is the branch, not noise)."""
KNEE_SEARCH_SHARE = 0.5
"""The knee is searched from where the current has closed this share of its gap to the
release line (before that the turn at the reversal can be slow for a moment)."""


def running_mean(y: FloatArray, half: int) -> FloatArray:
    """Mean over ``half`` samples either side (edges: the mean of the samples there are)."""
    kernel = np.ones(2 * half + 1)
    counts = np.convolve(np.ones(y.size), kernel, mode="same")
    return np.asarray(np.convolve(y, kernel, mode="same") / counts, dtype=np.float64)


def running_slope(y: FloatArray, half: int, step_deg: float) -> FloatArray:
    """Least-squares slope per deg over ``half`` samples either side (NaN at the edges)."""
    offsets = np.arange(-half, half + 1) * step_deg
    out = np.full(y.size, np.nan)
    if y.size > 2 * half:
        # correlate: sum over the window of offset x sample, the window centred on each sample
        out[half:y.size - half] = np.correlate(y, offsets, mode="valid") / float(
            np.sum(offsets ** 2))
    return out


def branch_scatter(grid: FloatArray, yg: FloatArray, stop: int | None = None) -> float | None:
    """The scatter of the current's running mean about its slow trend on the release branch
    (over ``RELEASE_LINE_WINDOW_DEG`` of travel, ended at ``stop``), robust; None where the
    branch is too short to tell."""
    step = float(grid[1] - grid[0])
    half, trend = round(KNEE_SLOPE_HALF_DEG / step), round(KNEE_TREND_HALF_DEG / step)
    end = yg.size if stop is None else min(stop, yg.size)
    x = grid - grid[0]
    sel = np.flatnonzero((x >= RELEASE_LINE_WINDOW_DEG[0]) & (x <= RELEASE_LINE_WINDOW_DEG[1]))
    sel = sel[(sel >= trend) & (sel < end - trend)]
    if sel.size * step < 2 * KNEE_TREND_HALF_DEG:
        return None
    r = running_mean(yg[:end], half) - running_mean(yg[:end], trend)
    return robust_sigma(r[sel])


def knee_index(grid: FloatArray, yg: FloatArray, stop: int | None = None) -> int | None:
    """The first point past the steep part of the approach where the current's slope over the
    release branch's (the 40-95 deg line) falls below its scatter per ``KNEE_TOLERANCE_DEG``;
    None where the branch cannot be read."""
    line = release_line(grid, yg, stop)
    scatter = branch_scatter(grid, yg, stop)
    if line is None or scatter is None:
        return None
    step = float(grid[1] - grid[0])
    half = round(KNEE_SLOPE_HALF_DEG / step)
    loaded = float(np.mean(yg[:max(1, round(0.5 / step))]))
    mean = running_mean(yg, half)
    gap = np.polyval(line, grid) - loaded
    moving = np.flatnonzero(mean - loaded >= KNEE_SEARCH_SHARE * gap)
    if moving.size == 0:
        return None
    rise = running_slope(yg, half, step) - float(line[0])
    slow = np.flatnonzero(rise[int(moving[0]):] < scatter / KNEE_TOLERANCE_DEG)
    return int(moving[0]) + int(slow[0]) if slow.size else None


def resolvable_end(grid: FloatArray, yg: FloatArray, end: int, stop: int | None = None) -> int:
    """A rule's backlash end ``end``, or the knee where that end lies beyond it (in the creep,
    where the current's scatter alone could have put it)."""
    knee = knee_index(grid, yg, stop)
    return end if knee is None else min(end, knee)
