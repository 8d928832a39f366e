"""What the motor current shows during ordinary motion: pure functions on arrays.

A *stroke* is one knob's motion between two reversals of its command. When a stroke goes out of
the dead zone, the tendon of that side engages and the direction-signed current climbs the
loaded ramp: current against knob angle is close to a line whose foot is the dead-zone edge. A
slack change moves that line along the knob axis by the change of the edge, a curvature change
also tilts it (more wrap, more friction), so the feature is the line itself, fitted robustly on
a window a few degrees beyond the edge, and the edge is where it crosses a fixed current level
(the level the ramp had at the calibrated edge, learned by the estimator).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tsmd.calibration.pieces import period_mean

Array = NDArray[np.float64]


@dataclass(frozen=True)
class Stroke:
    """One knob's samples between two reversals; ``direction`` +1 rising, -1 falling.

    Only samples where the knob moved are kept (standing still shows static friction, not the
    ramp). ``other_deg`` is the other knob's actual angle (the calibration grid's coordinate).
    """

    knob: int
    direction: int
    t_s: Array
    cmd_deg: Array
    pos_deg: Array
    current_A: Array
    other_deg: Array
    slip_deg: Array
    """Knob travel since it last stood still (or reversed): the handle's static friction
    fades over the first degrees after a restart and lifts the current there."""


@dataclass(frozen=True)
class RampOptions:
    """Where and how the loaded ramp is fitted; angles in knob degrees."""

    margin_deg: float = 8.0
    """The window starts this far beyond the expected edge (past the steep engagement)."""
    width_deg: float = 14.0
    """Knob travel the window spans; a stroke that turns back earlier gives no ramp."""
    min_samples: int = 20
    max_lag_deg: float = 3.0
    """|command - position| above this inside the window: the motor does not follow (stall)."""
    spike_sigma: float = 5.0
    """Samples further than this many robust sigmas from the first fit are dropped (spikes)."""
    handle_slip_deg: float = 3.0
    """Knob travel over which the handle's static friction fades to kinetic after a restart
    (a data-sheet constant of the handle; the simulated handle's). The fit carries a term
    ``exp(-slip / handle_slip_deg)`` for it, so a restart near the edge does not bend the line."""
    restart_skip_deg: float = 1.0
    """Samples closer than this to a restart are left out (the stick itself)."""
    knee_search_deg: float = 10.0
    """The knee (where the current leaves the dead zone's flat level) is searched this far
    either side of the expected edge ..."""
    knee_plateau_deg: float = 6.0
    """... with this much of the dead zone's flat current before the search range."""
    knee_step_deg: float = 0.25
    knee_min_side: int = 10
    """Samples needed on each side of a knee candidate."""
    torque_ripple_period_deg: float | None = None
    """The handle's torque ripple period (a detent's notch spacing; the data sheet's
    :attr:`tsmd.profile.DeviceKnob.torque_ripple_period_deg`): the loaded window's current is
    averaged over it before the line is fitted. None: no ripple, the samples are fitted."""
    ripple_grid_step_deg: float = 0.25
    """The uniform knob-angle grid the current is averaged on (bin means of the samples)."""
    load_drop_fraction: float = 0.0
    """A window whose current falls below its running maximum by more than this fraction of
    the fitted line's rise over the window gives no ramp: a knob moving outward on a loaded
    tendon only adds load, so a fall is the load path changing during the stroke (a shape
    change while the tendon is loaded: wormeyelet 4, +0.5 mm slack at 80 s in the middle of
    phi2's positive stroke, the current 0.148 -> 0.036 A; the line read +5.73 deg, the edge's
    later ramps +4.7..+4.8, and the follow stayed at +5.73). Off (0): with 0.5 the stored
    replays of coilpipe 1 and notchclutch 1-2 publish other targets, notchclutch's phi2
    ~1 deg further out (docs/online.md, "Session 27, round 2"); what is on instead keeps the
    ramp and takes no suspect from it
    (:attr:`tsmd.online.estimator_options.EstimatorOptions.cut_window_drop`)."""


@dataclass(frozen=True)
class LoadedRamp:
    """The direction-signed current over a window of the loaded ramp, as a line.

    ``side`` +1 is the tendon pulled by positive rotation (edge D_pos), -1 the other (D_neg).
    ``u`` is the knob angle signed by ``side`` (distance outward), so the ramp always rises.
    """

    knob: int
    side: int
    u0_deg: float
    current_at_u0_A: float
    slope_A_per_deg: float
    other_deg: float
    t_s: float
    n_samples: int
    noise_A: float
    knee_deg: float = math.nan
    """Knob angle where the current leaves the dead zone's flat level (:func:`find_knee_deg`);
    NaN when the stroke had too little of the dead zone or of the ramp around it."""
    knee_step_A: float = math.nan
    """The current's step up at the knee (the tendon engaging); for per-ramp diagnosis."""
    past_knee: bool = False
    """The window was placed past this stroke's own knee (not by the expected edge)."""
    speed_deg_s: float = math.nan
    """The knob's mean speed over the window: the sheath's friction, and so the current on the
    ramp, depends on it (coilpipe: strokes at 4-7 deg/s read 1-2.4 deg inward of those at
    ~20 deg/s)."""
    load_drop: float = 0.0
    """The window's largest fall of its (running-median) current below its running maximum,
    as a fraction of the line's rise over the window (:func:`load_drop`): a knob moving
    outward on a loaded tendon only adds load, so a fall is the load path changing during the
    stroke (:attr:`tsmd.online.estimator_options.EstimatorOptions.cut_window_reads_nothing`)."""

    def current_at(self, knob_deg: float) -> float:
        """The line's current at a knob angle."""
        return self.current_at_u0_A + self.slope_A_per_deg * (self.side * knob_deg - self.u0_deg)

    def crossing_deg(self, level_A: float, slope_A_per_deg: float | None = None) -> float:
        """Knob angle where the line crosses ``level_A`` (the edge for that level); with
        ``slope_A_per_deg``, the line through the window's centre with that slope instead."""
        slope = self.slope_A_per_deg if slope_A_per_deg is None else slope_A_per_deg
        return self.side * (self.u0_deg + (level_A - self.current_at_u0_A) / slope)


@dataclass(frozen=True)
class Rejected:
    """A stroke that gave no feature, and why (one line)."""

    knob: int
    reason: str
    stall: bool = False


RIPPLE_MIN_SPAN_DEG = 4.0
"""Knob travel the ripple-averaged points must span: each already averages a whole period, so
the line needs fewer degrees than the samples' fit (0.6 of the window)."""


def _line(x: Array, y: Array, stick: Array) -> tuple[float, float, Array]:
    """(value at mean x, slope, residuals) of the least-squares line plus a fading stick term
    (``stick`` = exp(-slip / handle_slip), left out when it does not vary in the window)."""
    xm = float(x.mean())
    columns = [np.ones_like(x), x - xm]
    if float(stick.max() - stick.min()) > 0.05:
        columns.append(stick)
    a_mat = np.column_stack(columns)
    coef, *_ = np.linalg.lstsq(a_mat, y, rcond=None)
    return float(coef[0]), float(coef[1]), y - a_mat @ coef


def _ripple_averaged(u: Array, y: Array, slip_deg: Array, start: float, o: RampOptions
                     ) -> tuple[Array, Array, Array] | None:
    """(angle, current, stick term) from ``start`` outward over the window, each averaged over
    one period of the handle's torque ripple (:func:`tsmd.calibration.pieces.period_mean`) on
    a uniform grid of knob angle: a periodic ripple of any shape averages out, the line stays.
    Each averaged point takes half a period of samples either side (inward of the window too),
    so the points end half a period before the stroke does; None where the stroke leaves
    fewer than 8 points or gaps (a restart) in a fifth of the grid."""
    period = float(o.torque_ripple_period_deg or 0.0)
    step = o.ripple_grid_step_deg
    half = max(1, round(0.5 * period / step))
    ok = slip_deg >= o.restart_skip_deg
    if not ok.any():
        return None
    lo = start - half * step
    hi = min(float(u[ok].max()), start + o.width_deg + half * step)
    n = math.floor((hi - lo) / step) + 1
    if n < 2 * half + 8:
        return None
    take = ok & (u >= lo - 0.5 * step) & (u < lo + (n - 0.5) * step)
    k = np.rint((u[take] - lo) / step).astype(int)
    counts = np.bincount(k, minlength=n)
    have = counts > 0
    if np.count_nonzero(have) < 0.8 * n:
        return None
    grid = lo + step * np.arange(n, dtype=np.float64)

    def binned(v: Array) -> Array:
        means = np.bincount(k, weights=v, minlength=n)[have] / counts[have]
        return np.interp(grid, grid[have], means)

    stick = np.exp(-slip_deg[take] / o.handle_slip_deg)
    x, y_mean = period_mean(grid, binned(y[take]), half, n - half, period)
    _, stick_mean = period_mean(grid, binned(stick), half, n - half, period)
    return x, y_mean, stick_mean


def _window(u: Array, slip_deg: Array, start: float, width: float, o: RampOptions,
            skip_deg: float | None = None) -> NDArray[np.bool_]:
    """Samples from ``start`` outward over ``width``; the window starts later where the knob
    restarted too close to it."""
    ok = slip_deg >= (o.restart_skip_deg if skip_deg is None else skip_deg)
    beyond = ok & (u >= start)
    if beyond.any():
        start = float(u[beyond].min())
    return beyond & (u <= start + width)


def _hinge_scan(x: Array, y: Array, stick: Array, lo: float, hi: float, o: RampOptions
                ) -> tuple[float, float, Array]:
    """(best knee in ``lo..hi``, the current's step up there, the residuals): flat, then a
    step up and a line, plus the handle's stick term when it varies; NaN and no residuals
    when no candidate fits."""
    with_stick = float(stick.max() - stick.min()) > 0.05
    best, best_step, best_sse, best_r = math.nan, math.nan, math.inf, np.zeros(0)
    for e in np.arange(lo, hi + 1e-9, o.knee_step_deg):
        out = x >= e
        n_out = int(np.count_nonzero(out))
        if n_out < o.knee_min_side or x.size - n_out < o.knee_min_side:
            continue
        columns = [~out, out, np.where(out, x - e, 0.0)]
        if with_stick:
            columns.append(stick)
        a_mat = np.column_stack(columns).astype(float)
        coef, *_ = np.linalg.lstsq(a_mat, y, rcond=None)
        r = y - a_mat @ coef
        sse = float(r @ r)
        if coef[1] > coef[0] and sse < best_sse:  # the current steps up out of the dead zone
            best, best_step, best_sse, best_r = float(e), float(coef[1] - coef[0]), sse, r
    return best, best_step, best_r


def find_knee_deg(stroke: Stroke, expected_edge_deg: float,
                  options: RampOptions | None = None) -> tuple[float, float]:
    """Where the current leaves the dead zone's flat level: the edge itself, seen in the stroke.

    A hinge is fitted by least squares for each candidate knee within ``knee_search_deg`` of
    the expected edge: flat inside, a step (the tendon engaging) and a line beyond, plus the
    handle's fading stick. Unlike a level crossing of the loaded line, the knee does not move
    when a sheath bend makes the engagement's step and the ramp steeper (capstan unit 1, 60 deg
    bend: the step at the knee 40 -> 50 mA, the ramp 1.3 x; a level crossing read the edge
    ~10 deg inward while the calibration's edge moved 4.8 deg outward). Returns (knee, the
    current's step up at it); NaN without enough samples either side.
    """
    o = options or RampOptions()
    side = stroke.direction
    u = side * stroke.pos_deg
    y = side * stroke.current_A
    e0 = side * expected_edge_deg
    lo, hi = e0 - o.knee_search_deg, e0 + o.knee_search_deg
    sel = ((stroke.slip_deg >= o.restart_skip_deg) & (u >= lo - o.knee_plateau_deg)
           & (u <= e0 + o.margin_deg + o.width_deg))
    x, y, stick = u[sel], y[sel], np.exp(-stroke.slip_deg[sel] / o.handle_slip_deg)
    if (np.count_nonzero(x < lo) < o.knee_min_side
            or not (np.all(np.isfinite(x)) and np.all(np.isfinite(y)))):
        return math.nan, math.nan  # too little of the dead zone's flat current before it
    best, step, r = _hinge_scan(x, y, stick, lo, hi, o)
    sigma = 1.4826 * float(np.median(np.abs(r - np.median(r)))) if r.size else 0.0
    if sigma > 0:  # spikes: dropped, then the scan again
        keep = np.abs(r) <= o.spike_sigma * sigma
        if not keep.all():
            best, step, _ = _hinge_scan(x[keep], y[keep], stick[keep], lo, hi, o)
    return (side * best, step) if math.isfinite(best) else (math.nan, math.nan)


def relocated_edge_deg(stroke: Stroke, expected_edge_deg: float, level_A: float,
                       slope_A_per_deg: float, options: RampOptions | None = None) -> float:
    """Where the edge is, from the reference ramp (level at the edge, slope), robustly.

    Each sample of the window beyond ``expected_edge_deg`` implies an edge: its angle minus
    the travel the reference ramp needs to climb from ``level_A`` to its current. Samples on
    the loaded ramp all imply the true edge; samples still in the dead zone (the edge has moved
    outward) imply edges further out, a minority as long as the window is mostly loaded, so the
    median is the edge. Used to move the fitting window when the edge has moved.
    """
    o = options or RampOptions()
    side = stroke.direction
    u = side * stroke.pos_deg
    start = side * expected_edge_deg + o.margin_deg
    sel = _window(u, stroke.slip_deg, start - o.margin_deg, o.margin_deg + o.width_deg, o,
                  3.0 * o.handle_slip_deg)
    if np.count_nonzero(sel) < o.min_samples:
        return expected_edge_deg
    implied = u[sel] - (side * stroke.current_A[sel] - level_A) / slope_A_per_deg
    implied = implied[np.isfinite(implied)]
    if implied.size < o.min_samples:
        return expected_edge_deg
    return side * float(np.median(implied))


LOAD_DROP_MEDIAN_SAMPLES = 9
"""The window's current is a running median over this many samples before its fall is taken:
the sensor's noise on a flat ramp (lumped, coilpipe) falls by up to 0.7 of the rise sample to
sample, the median by 0.70 at most in 43 recordings (planetwist 3), a load path change by
0.31 (planetwist 1) to 22."""


def load_drop(x: Array, y: Array, slope_A_per_deg: float) -> float:
    """The window's largest fall of its running-median current below its running maximum
    (samples in travel order), as a fraction of the line's rise over the window."""
    rise = slope_A_per_deg * float(x.max() - x.min())
    h = LOAD_DROP_MEDIAN_SAMPLES // 2
    padded = np.pad(y, h, mode="edge")
    smooth = np.median(np.lib.stride_tricks.sliding_window_view(padded, 2 * h + 1), axis=1)
    drop = float(np.max(np.maximum.accumulate(smooth) - smooth))
    return drop / rise if rise > 0 else math.inf


def loaded_ramp(stroke: Stroke, expected_edge_deg: float,
                options: RampOptions | None = None,
                knee: tuple[float, float] = (math.nan, math.nan)) -> LoadedRamp | Rejected:
    """The loaded ramp of a stroke that leaves the dead zone beyond ``expected_edge_deg``.

    ``expected_edge_deg`` is the edge of the stroke's side (D_pos for a rising stroke, D_neg
    for a falling one) where the ramp is expected to start (the stroke's knee,
    :func:`find_knee_deg`, or :func:`relocated_edge_deg`); ``knee`` (angle, step) is kept
    with the ramp.
    """
    o = options or RampOptions()
    side = stroke.direction
    u = side * stroke.pos_deg
    if float(u[0]) > side * expected_edge_deg - 1.0:
        return Rejected(stroke.knob, "the stroke did not start in the dead zone (no engagement)")
    start = side * expected_edge_deg + o.margin_deg
    sel = _window(u, stroke.slip_deg, start, o.width_deg, o)
    n = int(np.count_nonzero(sel))
    if n < o.min_samples:
        return Rejected(stroke.knob, f"{n} samples in the loaded window "
                                     f"({start:.1f}..{start + o.width_deg:.1f} deg outward)")
    x = u[sel]
    if float(x.max() - x.min()) < 0.6 * o.width_deg:
        return Rejected(stroke.knob, "the stroke turns back inside the loaded window")
    lag = np.abs(stroke.cmd_deg[sel] - stroke.pos_deg[sel])
    if float(lag.max()) > o.max_lag_deg:
        return Rejected(stroke.knob, f"the motor lags its command by {float(lag.max()):.1f} deg "
                                     "(stalled or blocked)", stall=True)
    y = side * stroke.current_A[sel]
    if not (np.all(np.isfinite(y)) and np.all(np.isfinite(x))):
        return Rejected(stroke.knob, "non-finite samples in the loaded window")
    stick = np.exp(-stroke.slip_deg[sel] / o.handle_slip_deg)
    span_s = float(stroke.t_s[sel][-1] - stroke.t_s[sel][0])
    speed = float(x.max() - x.min()) / span_s if span_s > 0 else math.nan
    if o.torque_ripple_period_deg:
        averaged = _ripple_averaged(u, side * stroke.current_A, stroke.slip_deg,
                                    float(x.min()), o)
        if averaged is None or float(averaged[0][-1] - averaged[0][0]) < RIPPLE_MIN_SPAN_DEG:
            return Rejected(stroke.knob, "the stroke turns back within half a torque ripple "
                                         "period of the loaded window")
        x, y, stick = averaged
    a, b, r = _line(x, y, stick)
    sigma = 1.4826 * float(np.median(np.abs(r - np.median(r))))
    if sigma > 0:
        keep = np.abs(r) <= o.spike_sigma * sigma
        if np.count_nonzero(keep) >= o.min_samples and not keep.all():
            x, y, stick = x[keep], y[keep], stick[keep]
            a, b, r = _line(x, y, stick)
    if not b > 0:
        return Rejected(stroke.knob, "the current does not rise in the loaded window")
    drop = load_drop(x, y, b)
    if o.load_drop_fraction > 0.0 and drop > o.load_drop_fraction:
        return Rejected(stroke.knob, "the current falls inside the loaded window (the load "
                                     "path changed during the stroke)")
    noise = float(np.sqrt(np.mean(r * r))) if r.size else math.nan
    return LoadedRamp(stroke.knob, side, float(x.mean()), a, b,
                      float(np.median(stroke.other_deg[sel])), float(stroke.t_s[sel][-1]),
                      int(x.size), noise, knee[0], knee[1],
                      expected_edge_deg == knee[0], speed, drop)
