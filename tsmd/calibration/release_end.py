"""Where the release ends, read from the calibration's motor current (session 18).

After a reversal at +A the knob gives the loaded tendon's stretch back (the backlash), then the
tip follows the release path down to the plateau, where that tendon goes slack. On products
whose released tendon still carries a share of the load (ratestate: the sheath's rate-and-state
friction), the knob's current keeps ramping down over the release and turns flat where the
tendon goes slack: the release's end is a kink in the current. Method ours draws the unit's
release line from its own backlash end at the amplitude to that point at the plateau, so the
release no longer hangs on the unit's loaded slope times the product's ratio
(:func:`release_end_ratios`).

The reading (:func:`read_release_end`), per side over every half-cycle after a reversal at that
side's amplitude (all sweeps of the knob pooled): the current, mirrored so that the ramp rises
toward the reversal, between the far dead-zone edge and the backlash end (each with a margin),
fitted by a flat joined at ``x_e`` to a quadratic ramp, ``c = a + s h + q h^2`` with ``h =
max(x - x_e, 0)`` (the ramp steepens toward its end: a straight ramp put the kink 4 deg late on
ratestate development units 1-2, the quadratic 1 deg); its uncertainty by the jackknife over the
half-cycles (each left out once). The fit uses the low-passed current the calibration already
has; pooling hundreds of samples per degree makes the drive's 2 mA steps and noise average out.
What the current's kink is not is the tip's end: the product's offset between the two, measured
on the data sheet's unit with the tracker (``reference_release_end_offset_deg``,
:mod:`tsmd.datasheet_release_end`), is added; a sheet without it does not read the end at all.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.calibration.identify import split_half_cycles
from tsmd.calibration.options import IdentifyOptions

FloatArray = NDArray[np.float64]

WINDOW_MARGIN_DEG = 5.0
"""The fit starts this far past the far dead-zone edge and stops this far before the backlash
end (the other tendon's loading and the backlash's own transient stay out)."""
SEARCH_MARGIN_DEG = 3.0
"""The kink is searched this far inside the window (a kink at the window's end is no kink)."""
COARSE_STEP_DEG = 0.5
FINE_STEP_DEG = 0.05
MIN_HALF_CYCLES = 3
"""Fewer half-cycles on a side than this: no jackknife, no reading."""
MAX_END_U95_DEG = 2.0
"""A side whose reading is more uncertain than this (95 %) keeps the product's ratio."""
MIN_RAMP_RISE = 4.0
"""The ramp must rise above the flat by this many times the fit's residual scatter over the
window (a flat current has a kink anywhere)."""
REVERSAL_SHARE = 0.9
"""A half-cycle counts for a side when it starts beyond this share of the sweep's amplitude."""


@dataclass(frozen=True)
class ReleaseEnd:
    """One side's reading: the knob angle (signed, as the knob moves) where the current's
    release ramp turns flat, its 95 % uncertainty, the half-cycles it pooled and the flat's
    level (signed; the friction current, or on the tracked tip its plateau in deg)."""

    end_deg: float
    u95_deg: float
    half_cycles: int
    level: float


@dataclass(frozen=True)
class _Piece:
    x_deg: FloatArray
    y: FloatArray


class _Sums:
    """Suffix sums of x^p (p <= 4), x^p y (p <= 2) and y^2 over the samples sorted by x, so
    that the least-squares fit at any ``x_e`` costs a 3x3 solve (h = x - x_e beyond it)."""

    def __init__(self, x: FloatArray, y: FloatArray) -> None:
        order = np.argsort(x)
        self.x = x[order]
        ys = y[order]
        powers = np.vstack([self.x ** p for p in range(5)])
        self.px = np.concatenate([np.cumsum(powers[:, ::-1], axis=1)[:, ::-1],
                                  np.zeros((5, 1))], axis=1)
        self.pxy = np.concatenate([np.cumsum((powers[:3] * ys)[:, ::-1], axis=1)[:, ::-1],
                                   np.zeros((3, 1))], axis=1)
        self.n = float(x.size)
        self.sy = float(ys.sum())
        self.syy = float(ys @ ys)

    def fit(self, end_deg: float) -> tuple[float, FloatArray]:
        """Residual sum of squares and (a, s, q) of ``a + s h + q h^2``, h = max(x - x_e, 0)."""
        i = int(np.searchsorted(self.x, end_deg, side="right"))
        e = end_deg
        m0, m1, m2, m3, m4 = (float(v) for v in self.px[:, i])
        c0, c1, c2 = (float(v) for v in self.pxy[:, i])
        h1 = m1 - e * m0  # sums of h^p over the ramp's samples, from the powers of x
        h2 = m2 - 2 * e * m1 + e * e * m0
        h3 = m3 - 3 * e * m2 + 3 * e * e * m1 - e ** 3 * m0
        h4 = m4 - 4 * e * m3 + 6 * e * e * m2 - 4 * e ** 3 * m1 + e ** 4 * m0
        hy = c1 - e * c0
        h2y = c2 - 2 * e * c1 + e * e * c0
        a = np.array([[self.n, h1, h2], [h1, h2, h3], [h2, h3, h4]])
        b = np.array([self.sy, hy, h2y])
        try:
            coef = np.linalg.solve(a, b)
        except np.linalg.LinAlgError:
            return math.inf, np.zeros(3)
        return max(self.syy - float(coef @ b), 0.0), coef


def kink(x: FloatArray, y: FloatArray, lo_deg: float, hi_deg: float) -> tuple[float, float]:
    """The ``x_e`` in [lo, hi] of the least-squares flat-plus-quadratic-ramp (coarse grid, then
    a fine one around its best) and the flat's level; NaNs when the best ramp does not rise
    toward the reversal."""
    if not hi_deg > lo_deg:
        return math.nan, math.nan
    sums = _Sums(x, y)
    coarse = np.arange(lo_deg, hi_deg + 1e-9, COARSE_STEP_DEG)
    best = min(coarse, key=lambda e: sums.fit(float(e))[0])
    fine = np.arange(max(lo_deg, best - COARSE_STEP_DEG),
                     min(hi_deg, best + COARSE_STEP_DEG) + 1e-9, FINE_STEP_DEG)
    end = float(min(fine, key=lambda e: sums.fit(float(e))[0]))
    rss, (level, s, q) = sums.fit(end)
    run = float(np.max(x)) - end
    rise = s * run + q * run * run
    scatter = math.sqrt(rss / max(x.size - 3, 1))
    if not (s > 0 and rise > MIN_RAMP_RISE * scatter):
        return math.nan, math.nan
    return end, float(level)


def _side_pieces(sweeps: Sequence[Any], sign: int, min_reversal_deg: float
                 ) -> tuple[list[_Piece], float, float]:
    """Each half-cycle after a reversal at ``sign``'s amplitude, mirrored (x = sign pos,
    y = sign current) and cut to its window; and the pooled search range."""
    pieces: list[_Piece] = []
    los: list[float] = []
    his: list[float] = []
    for s in sweeps:
        pos = sign * np.asarray(s.pos_deg, float)
        cur = sign * np.asarray(s.current_A, float)
        cmd = sign * np.asarray(s.cmd_deg, float)
        amplitude = float(np.max(cmd))
        far_edge = s.dead_zone_neg_deg if sign > 0 else -s.dead_zone_pos_deg  # mirrored
        backlash = s.backlash_pos_deg if sign > 0 else s.backlash_neg_deg
        if not (math.isfinite(far_edge) and math.isfinite(backlash)):
            continue
        for direction, a, b, _ in split_half_cycles(cmd, min_reversal_deg):
            if direction > 0 or cmd[a] < REVERSAL_SHARE * amplitude:
                continue
            x, y = pos[a:b], cur[a:b]
            lo = far_edge + WINDOW_MARGIN_DEG
            hi = float(np.max(x)) - backlash - WINDOW_MARGIN_DEG
            keep = (x > lo) & (x < hi) & np.isfinite(y)
            if np.count_nonzero(keep) < 20:
                continue
            pieces.append(_Piece(x[keep], y[keep]))
            los.append(lo)
            his.append(hi)
    if not pieces:
        return pieces, math.nan, math.nan
    return pieces, max(los) + SEARCH_MARGIN_DEG, min(his) - SEARCH_MARGIN_DEG


def read_release_end(sweeps: Sequence[Any], sign: int,
                     min_reversal_deg: float = IdentifyOptions().min_reversal_deg
                     ) -> ReleaseEnd | None:
    """One side's release end from the current of ``sweeps`` (objects with ``pos_deg``,
    ``cmd_deg``, ``current_A``, ``dead_zone_*_deg`` and ``backlash_*_deg``, as
    :class:`tsmd.calibration.tension_play_fit.SweepCurrent`); None where the current shows no
    kink or too few half-cycles."""
    pieces, lo, hi = _side_pieces(sweeps, sign, min_reversal_deg)
    if len(pieces) < MIN_HALF_CYCLES:
        return None
    x = np.concatenate([p.x_deg for p in pieces])
    y = np.concatenate([p.y for p in pieces])
    end, level = kink(x, y, lo, hi)
    if not math.isfinite(end):
        return None
    left_out = []
    for i in range(len(pieces)):
        rest = pieces[:i] + pieces[i + 1:]
        left_out.append(kink(np.concatenate([p.x_deg for p in rest]),
                             np.concatenate([p.y for p in rest]), lo, hi)[0])
    jk = np.asarray(left_out, float)
    n = jk.size
    if not np.isfinite(jk).all():
        return ReleaseEnd(sign * end, math.inf, n, sign * level)
    sd = math.sqrt((n - 1) / n * float(np.sum((jk - jk.mean()) ** 2)))
    return ReleaseEnd(sign * end, 1.96 * sd, n, sign * level)


def release_end_ratio(end_deg: float, backlash_end_deg: float, top_deg: float,
                      plateau_deg: float, locus_slope: float) -> float:
    """The ratio of the release line through the backlash end (``backlash_end_deg``,
    ``top_deg``: knob and tip there) and the release's end at the plateau (``end_deg``,
    ``plateau_deg``) to the locus slope; NaN where the points give no rising line."""
    run = backlash_end_deg - end_deg
    rise = top_deg - plateau_deg
    if not (run * rise > 0 and locus_slope > 0):
        return math.nan
    return rise / run / locus_slope


def end_ratio(sweeps: Sequence[Any], sign: int, offset_deg: float,
              backlash_end_deg: Sequence[float], top_deg: Sequence[float], plateau_deg: float,
              locus_slope: Sequence[float], fallback: float,
              ratio_range: tuple[float, float]) -> float:
    """One side's release-path ratio from its release end (the current's kink plus the
    product's ``offset_deg``, away from the dead zone), the mean over the sweeps' backlash ends
    (knob, tip) and locus slopes; ``fallback`` (the product's ratio) where the current shows no
    kink, the reading is more uncertain than :data:`MAX_END_U95_DEG` or the ratio is outside
    ``ratio_range``."""
    reading = read_release_end(sweeps, sign)
    if reading is None or not reading.u95_deg <= MAX_END_U95_DEG:
        return fallback
    end = reading.end_deg + sign * offset_deg
    ratios = [release_end_ratio(end, xb, top, plateau_deg, slope)
              for xb, top, slope in zip(backlash_end_deg, top_deg, locus_slope, strict=True)]
    ratio = float(np.mean(ratios))
    lo, hi = ratio_range
    return ratio if lo <= ratio <= hi else fallback


def plateau_moved(device_knob: Any, omega: float, h_pos: float, h_neg: float,
                  d_pos: Sequence[float], d_neg: Sequence[float]
                  ) -> tuple[float, float, list[float], list[float]]:
    """Where the sheet has its unit's tracked plateau (``reference_release_plateau_deg``), the
    plateaus the release is drawn to are the product's (rising ``-P``, falling ``+P``) and each
    edge moves along its loaded line so that the line stays (``H + omega (x - D)`` unchanged);
    else as given. The straight line through the reference point puts ratestate's plateau
    1.4-1.9 deg short of its tip's (5.31 / 7.02 against 7.24 / 7.65 on the sheet's unit)."""
    level = getattr(device_knob, "reference_release_plateau_deg", None)
    if level is None:
        return h_pos, h_neg, list(d_pos), list(d_neg)
    new_pos, new_neg = -float(level), float(level)
    return (new_pos, new_neg, [d + (new_pos - h_pos) / omega for d in d_pos],
            [d + (new_neg - h_neg) / omega for d in d_neg])


def side_ratios(sweeps: Sequence[Any], device_knob: Any, omega: float,
                heights: tuple[float, float],
                edges: tuple[Sequence[float], Sequence[float]],
                gains: tuple[Sequence[float], Sequence[float]],
                zero_loads: tuple[Sequence[float], Sequence[float]], fallback: float,
                ratio_range: tuple[float, float]) -> tuple[float, float]:
    """Each side's release-path ratio from its release end (:func:`end_ratio`): the line from
    each sweep's backlash end on its loaded line (``A - beta (A - x0)``, ``H + omega (A -
    D)``) to the end at the other side's plateau (the falling branch's after a positive
    reversal)."""
    offset = float(device_knob.reference_release_end_offset_deg)
    out = []
    for i, sign in enumerate((1, -1)):
        amplitude = [float(np.max(sign * np.asarray(s.pos_deg, float))) * sign for s in sweeps]
        ends = [a - b * (a - x0)
                for a, b, x0 in zip(amplitude, gains[i], zero_loads[i], strict=True)]
        tops = [heights[i] + omega * (a - d) for a, d in zip(amplitude, edges[i], strict=True)]
        out.append(end_ratio(sweeps, sign, offset, ends, tops, heights[1 - i],
                             [omega / (1.0 - b) for b in gains[i]], fallback, ratio_range))
    return out[0], out[1]
