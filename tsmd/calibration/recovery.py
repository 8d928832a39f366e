"""Where the backlash ends behind a self-locking handle: the end of the current's recovery.

On a handle whose collar holds the bend by itself (a self-locking lead screw: the screwrod
plant) the thread's friction turns round within about 1 deg of a reversal, and the knob's
torque then carries the releasing tendon only through the collar's back-driven factor: the
current jumps to about its release level at once, overshoots it by what the still-loaded tendon
adds (1-20 % of the swing, by the unit's thread friction), and recovers to the level as the
tendon unloads; the tip moves once it has (docs/calibration.md, sessions 15 and 16). The
settle rule ends B where the overshoot has fallen into the noise band, short by as much as the
band hides; a threshold relative to the overshoot cannot place the end where it is a few mA.

Here the recovery is fitted as a hinge, ``y = a + b x + c (e - x)+`` (``c > 0``) from the
overshoot's peak over :data:`RECOVERY_FIT_DEG`: the level (a line, the release branch) and a
straight recovery meeting at ``e``, every sample weighing in, so the end does not depend on the
noise band. The product's lag from ``e`` to the tip's release is measured on the data sheet's
unit (``DeviceKnob.backlash_recovery_lag_deg``). How much better the hinge explains the current
than the line alone, in the change-point penalty's units (noise variance x log n), says whether
the recovery can be seen at all (:func:`recovery_end`'s ``visibility``); where it cannot, no
share, slope or fit of the current places B, and :func:`unseen_backlash_deg` says what the
calibration uses instead.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tsmd.calibration.options import BacklashReference, IdentifyOptions
from tsmd.calibration.signal import FloatArray
from tsmd.calibration.sweep_result import SweepResult

RECOVERY_LEVEL_WINDOW_DEG = (20.0, 30.0)
"""Knob travel after the reversal over which the release level is the current's median (past
the family's screwrod backlashes, 7-15 deg, short of the dead-zone edge on the far side)."""
RECOVERY_PEAK_DEG = 3.0
"""The overshoot's peak is searched this far past where the current first reaches the level."""
RECOVERY_FIT_DEG = 25.0
"""Knob travel from the peak over which the hinge is fitted."""
RECOVERY_MIN_SIDE_DEG = 2.0
"""The hinge's corner is searched at least this far inside the fitted window's end."""


@dataclass(frozen=True)
class Recovery:
    """The recovery's end (an index into the half-cycle's angle grid) and how clearly the
    current shows it (the hinge's residual gain over a line, in noise variance x log n)."""

    end: int
    visibility: float


def recovery_end(grid: FloatArray, yg: FloatArray, noise_A: float,
                 stop: int | None = None) -> Recovery | None:
    """The end of the current's recovery from its overshoot after a reversal (see the module
    docstring), on the direction-signed current ``yg`` over ``grid``; None where the current
    never reaches its release level or too little of the half-cycle is left to fit."""
    step = float(grid[1] - grid[0])
    end = yg.size if stop is None else min(stop, yg.size)
    x = grid[:end] - grid[0]
    y = yg[:end]
    lo, hi = RECOVERY_LEVEL_WINDOW_DEG
    level_sel = (x >= lo) & (x <= hi)
    if np.count_nonzero(level_sel) < 5:
        return None
    level = float(np.median(y[level_sel]))
    reached = np.flatnonzero(y >= level)
    if reached.size == 0:
        return None
    k0 = int(reached[0])
    peak = k0 + int(np.argmax(y[k0:k0 + round(RECOVERY_PEAK_DEG / step) + 1]))
    b = min(end, peak + round(RECOVERY_FIT_DEG / step) + 1)
    xs, ys = x[peak:b], y[peak:b]
    corners = np.arange(xs[0] + step, xs[-1] - RECOVERY_MIN_SIDE_DEG, step)
    if xs.size < 8 or corners.size == 0:
        return None
    rss, slope = _hinge_rss(xs, ys, corners)
    rss = np.where(slope > 0.0, rss, np.inf)
    line = np.polyfit(xs, ys, 1)
    rss_line = float(np.sum((ys - np.polyval(line, xs)) ** 2))
    if not np.isfinite(rss).any():
        return Recovery(peak, 0.0)
    i = int(np.argmin(rss))
    gain = (rss_line - float(rss[i])) / (max(noise_A, 1e-12) ** 2 * math.log(xs.size))
    return Recovery(min(peak + round((corners[i] - xs[0]) / step), end - 1), max(gain, 0.0))


def _hinge_rss(x: FloatArray, y: FloatArray, corners: FloatArray
               ) -> tuple[FloatArray, FloatArray]:
    """For each corner e: the residual sum of squares of ``a + b x + c (e - x)+`` and ``c``."""
    h = np.maximum(corners[:, None] - x[None, :], 0.0)
    basis = np.stack([np.ones_like(h), np.broadcast_to(x, h.shape), h], axis=2)
    gram = np.einsum("mni,mnj->mij", basis, basis) + 1e-12 * np.eye(3)
    coef = np.linalg.solve(gram, np.einsum("mni,n->mi", basis, y)[..., None])[..., 0]
    fit = np.einsum("mni,mi->mn", basis, coef)
    return ((y[None, :] - fit) ** 2).sum(1), coef[:, 2]


BACKLASH_SWING_EXPONENT = 0.78
"""A healthy unit's backlash grows with its current's swing after a reversal:
B ~ swing ** 0.78 (development units 1-8 of both plants, fast sweeps, other knob at 0; one
exponent, each plant anchored on its own units; log residual sd 0.09 on both)."""
BACKLASH_SWING_SCATTER = 0.09
"""Log standard deviation of a healthy unit's backlash about :data:`BACKLASH_SWING_EXPONENT`'s
law (same fit)."""


def expected_backlash_deg(reference_deg: float, swing_A: float,
                          reference_swing_A: float) -> float:
    """The backlash a unit whose current swings ``swing_A`` after a reversal should show, from
    the data-sheet unit's (``reference_deg`` at ``reference_swing_A``)."""
    return reference_deg * (swing_A / reference_swing_A) ** BACKLASH_SWING_EXPONENT


UNSEEN_U95_SHARE = 0.25
"""95 % half-width of a backlash taken from the data sheet where the current does not show it,
as a share of that backlash: the law of :func:`unseen_backlash_deg` (unit 0's bend gains)
against the tip on screwrod development units 1-8 (fast sweeps, noise seed 0, all 192
half-cycles after a reversal, seen or not, every other-knob angle): 95 % of its errors within
23 % of the value (31 % at the other knob's 0, 21-22 % at +-90; without the bend gain 38 %)."""


def unseen_backlash_deg(reference: BacklashReference, name: str, swing_A: float,
                        other_deg: float) -> tuple[float, float]:
    """(backlash, its 95 % half-width) where the current does not show where the backlash ends:
    the data sheet's reference backlash (its unit, other knob at 0) scaled by this
    half-cycle's own swing (:func:`expected_backlash_deg`) and by the sheet's bend gain at the
    other knob's angle (linear in its size, the gain at 90 deg), with
    :data:`UNSEEN_U95_SHARE`."""
    ref = reference.pos_deg if name == "backlash_pos_deg" else reference.neg_deg
    bend = 1.0 + (reference.bend_gain - 1.0) * min(abs(other_deg), 90.0) / 90.0
    value = bend * expected_backlash_deg(ref, max(swing_A, 1e-9), reference.swing_A)
    return value, UNSEEN_U95_SHARE * value


def with_unseen(result: SweepResult, opts: IdentifyOptions | None,
                other_deg: float) -> SweepResult:
    """``result`` with each backlash that no half-cycle of the sweep shows (rule "recovery",
    a sheet reference given) set to :func:`unseen_backlash_deg` per half-cycle and flagged in
    ``result.unseen`` with the largest half-width (unchanged otherwise)."""
    if opts is None or opts.backlash != "recovery" or opts.unseen_backlash is None:
        return result
    values = dict(result.values)
    unseen: dict[str, float] = {}
    for name in ("backlash_pos_deg", "backlash_neg_deg"):
        if values.get(name):
            continue
        read = [unseen_backlash_deg(opts.unseen_backlash, name, h.release_swing_A, other_deg)
                for h in result.half_cycles
                if h.backlash_name == name and math.isfinite(h.release_swing_A)]
        if read:
            values[name] = tuple(v for v, _ in read)
            unseen[name] = max(u for _, u in read)
    return dataclasses.replace(result, values=values, unseen=unseen) if unseen else result


def bend_gain(points: Sequence[tuple[float, float, float]], reference_deg: float,
              reference_swing_A: float) -> float:
    """The sheet's bend gain from its own unit: ``points`` holds (other-knob angle, the tip's
    backlash, the current's swing) per grid point and side; the tip's backlash over the
    swing law's at the other knob's +-90 deg over the same at 0 (NaN without both)."""
    def ratio(far: bool) -> list[float]:
        return [b / expected_backlash_deg(reference_deg, s, reference_swing_A)
                for o, b, s in points if (abs(o) >= 89.0) == far and (far or abs(o) < 1.0)]
    far, zero = ratio(True), ratio(False)
    return float(np.mean(far) / np.mean(zero)) if far and zero else math.nan
