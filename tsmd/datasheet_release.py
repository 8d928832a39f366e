"""What the data sheet reads at each reversal of its tracked sweep: the current's share of
the way back at the tip's release under each backlash rule, the slope ratio, the swing.

Kept apart from :mod:`tsmd.datasheet` (the sheet's whole-pass constants) because each rule of
:mod:`tsmd.calibration.release` adds its read here.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from tsmd.calibration.identify import resample_on_angle, split_half_cycles
from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.pieces import smooth_value
from tsmd.calibration.release import (
    RELEASE_LEVEL_WINDOW_DEG,
    line_share_at,
    loaded_current,
    local_share_at,
    release_line,
    release_slope_ratio,
)
from tsmd.calibration.signal import Conditioned, lowpass
from tsmd.tip_truth import TIP_THRESHOLD_DEG

READ_FROM_DEG = 80.0
"""Reversals read: those beyond this knob angle (the ends of the sheet's +-90 deg sweep, not a
grid sweep's smaller amplitudes)."""


def backlash_settle_fraction(data: Conditioned, tip_t_s: NDArray[np.float64],
                             tip_deg: NDArray[np.float64],
                             options: IdentifyOptions | None = None) -> float | None:
    """How far the (filtered) current has come back when the tip starts to move after a
    reversal at the sweep's ends, as a share of its swing from the loaded current to the
    release level; median over the reversals (:func:`release_reads`)."""
    return median_share(release_reads(data, tip_t_s, tip_deg, options))


def backlash_release_slope_ratio(data: Conditioned, tip_t_s: NDArray[np.float64],
                                 tip_deg: NDArray[np.float64],
                                 options: IdentifyOptions | None = None) -> float | None:
    """The current's release-to-loaded slope ratio after the tip's release
    (:func:`tsmd.calibration.release.release_slope_ratio`), median over the reversals: the
    anchor from which each calibrated unit's own ratio moves the share."""
    return median_ratio(release_reads(data, tip_t_s, tip_deg, options))


class ReleaseRead(NamedTuple):
    """What one reversal gives the sheet (:func:`release_reads`)."""

    share: float
    ratio: float
    swing_A: float
    settle_lag_deg: float = math.nan
    """Knob travel from the settle rule's end to the tip's release."""
    line_share: float = math.nan
    """The share of the gap to the release line closed at the tip's release."""
    local_share: float = math.nan
    """The share of the gap to the branch just beyond the tip's release closed there."""


def median_share(reads: Sequence[ReleaseRead]) -> float | None:
    """The sheet's release share: median over the reversals' reads (None: no reversal)."""
    return float(np.median([r.share for r in reads])) if reads else None


def median_ratio(reads: Sequence[ReleaseRead]) -> float | None:
    """The sheet's slope ratio: median over the reversals' finite reads (None: none)."""
    ratios = [r.ratio for r in reads if math.isfinite(r.ratio)]
    return float(np.median(ratios)) if ratios else None


def release_reads(data: Conditioned, tip_t_s: NDArray[np.float64], tip_deg: NDArray[np.float64],
                  options: IdentifyOptions | None = None,
                  settle_deg: Mapping[int, float] | None = None) -> list[ReleaseRead]:
    """Share of the swing, release-to-loaded slope ratio and swing at the tip's release after
    each reversal at the sweep's ends.

    Measured with the definitions they are used with, or they do not transfer: the tip as the
    scoring truth reads it (low-passed at the current's cutoff, then 1 deg back: on the raw
    tracker the noise fired the threshold 1.5-2.5 deg early), and the current as the
    calibration's fraction rule reads it (the identification's half-cycles on the angle grid
    without the last ``edge_margin_deg``, :func:`~tsmd.calibration.release.loaded_current`, the
    release level over ``RELEASE_LEVEL_WINDOW_DEG`` after the tip's release, the value there
    off the same quadratic). The one sample at the position's turning point, used before,
    still carries the motor's friction half-turned (docs/calibration.md, session 7).
    ``settle_deg``: the settle rule's backlash per half-cycle start (the sheet's own
    identification), for the tip's lag behind it."""
    opts = options if options is not None else IdentifyOptions()
    step = opts.grid_step_deg
    tip_f, _ = lowpass(np.asarray(tip_deg, dtype=float), 1.0 / float(np.median(np.diff(tip_t_s))))
    tip = np.interp(data.t_s, tip_t_s, tip_f)
    lo_deg, hi_deg = RELEASE_LEVEL_WINDOW_DEG
    reads = []
    for direction, a, b, after_reversal in split_half_cycles(data.cmd_deg, 10.0):
        if not after_reversal or abs(data.pos_deg[a]) < READ_FROM_DEG:
            continue
        pos = data.pos_deg[a:b]
        grid, yg = resample_on_angle(pos, direction * data.current_filtered_A[a:b], direction,
                                      step)
        _, tg = resample_on_angle(pos, direction * tip[a:b], direction, step)
        moved = np.flatnonzero(tg - tg[0] > TIP_THRESHOLD_DEG)
        if grid.size < 6 or moved.size == 0:
            continue
        k = int(moved[0])
        free = (grid > grid[k] + lo_deg) & (grid < grid[k] + hi_deg)
        if np.count_nonzero(free) < 5:
            continue
        loaded = loaded_current(yg, step)
        swing = float(np.median(yg[free])) - loaded
        if swing <= 0.0:
            continue
        made_up = smooth_value(grid, yg, k, opts.release_fit_half_deg) - loaded
        cut = yg.size - round(opts.edge_margin_deg / step)
        settled = math.nan if settle_deg is None else settle_deg.get(a, math.nan)
        line = release_line(grid[:cut], yg[:cut])
        reads.append(ReleaseRead(
            min(made_up / swing, 1.0), release_slope_ratio(grid[:cut], yg[:cut], k), swing,
            float(grid[k] - grid[0]) - settled,
            math.nan if line is None else line_share_at(grid, yg, k, line,
                                                        opts.release_fit_half_deg),
            local_share_at(grid[:cut], yg[:cut], k, opts.release_fit_half_deg)))
    return reads
