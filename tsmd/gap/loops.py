"""Matched residual loops: sampled at the same knob angles, compared between condition levels.

The protocol's loops run on a lattice of knob angles shared by every level, so the residual
(data minus the physics simulator) of matched loops is compared sample by sample; the base
mismatch is the same in all of them and cancels in the level contrast. A one-way analysis of
variance against the repeats says whether the levels differ; a small effect model fitted on one
configuration's contrast and scored on another's says how much of the contrast the effect takes.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import stats

FloatArray = NDArray[np.float64]
Triple = tuple[FloatArray, FloatArray, FloatArray]
"""One channel of a matched loop: knob angle, residual, measured tip."""


@dataclass
class Loops:
    """One test in one configuration: residual loops sampled at matched knob angles."""

    y: FloatArray  # (levels, reps, K) residual at the matched points
    tip: FloatArray  # (K,) the measured loop, mean over levels and repeats
    knob: FloatArray  # (K,) the knob angle of each point
    dirn: FloatArray  # (K,) +1 rising branch, -1 falling
    part: FloatArray  # (K,) which knob / channel the point belongs to
    span_deg: float = 1.0
    """Knob angle (deg) of ``knob`` = 1: the loops' amplitude."""
    ref_noise_ss: float = 0.0
    """Noise a subtracted reference contrast brings (:mod:`tsmd.gap.reference`)."""


def _branches(knob: FloatArray) -> tuple[NDArray[np.bool_], NDArray[np.bool_]]:
    """Row masks of the falling and the rising branch of one closed loop (+A -> -A -> +A)."""
    turn = int(np.argmin(knob))
    idx = np.arange(len(knob))
    return idx <= turn, idx >= turn


def _sample(knob: FloatArray, resid: FloatArray, grid: FloatArray) -> FloatArray:
    """The residual of one branch at the grid's knob angles (exact on the protocol's lattice)."""
    x, first = np.unique(knob, return_index=True)
    return np.asarray(np.interp(grid, x, resid[first]))


def loop_contrast(windows: dict[tuple[str, int], list[Triple | None]],
                  levels: Sequence[str]) -> Loops | None:
    """Residual loops per (level, rep) on the knob angles of the sparsest window.

    ``windows[(level, rep)]`` is a list of (knob, residual, measured) triples, one per
    compared channel, all of the same closed loop; every (level, rep) must be present.
    """
    keys = [(lv, r) for lv in levels for r in (0, 1)]
    if any(k not in windows or any(w is None for w in windows[k]) for k in keys):
        return None
    full: dict[tuple[str, int], list[Triple]] = {
        k: [w for w in windows[k] if w is not None] for k in keys}
    n_parts = len(full[keys[0]])
    ys: dict[tuple[str, int], list[FloatArray]] = {k: [] for k in keys}
    ds, ps, tips, xs = [], [], [], []
    span_deg = 1.0
    for p in range(n_parts):
        sparse = min(keys, key=lambda k: len(full[k][p][0]))
        knob_ref = full[sparse][p][0]
        fall_ref, rise_ref = _branches(knob_ref)
        margin = 0.02 * float(np.ptp(knob_ref))
        lo, hi = float(knob_ref.min()) + margin, float(knob_ref.max()) - margin
        grids = []
        for mask, sign in ((fall_ref, -1.0), (rise_ref, 1.0)):
            x = knob_ref[mask]
            grids.append((np.unique(x[(x > lo) & (x < hi)]), sign))
        meas = []
        for k in keys:
            knob, resid, measured = full[k][p]
            fall, rise = _branches(knob)
            pairs = list(zip((fall, rise), grids, strict=True))
            ys[k].append(np.concatenate([_sample(knob[m], resid[m], g) for m, (g, _) in pairs]))
            meas.append(np.concatenate([_sample(knob[m], measured[m], g) for m, (g, _) in pairs]))
        tips.append(np.mean(meas, axis=0))
        span_deg = max(float(np.abs(knob_ref).max()), 1e-9)
        for grid, sign in grids:
            xs.append(grid / span_deg)
            ds.append(np.full(len(grid), sign))
            ps.append(np.full(len(grid), float(p)))
    y = np.array([[np.concatenate(ys[(lv, r)]) for r in (0, 1)] for lv in levels])
    return Loops(y, np.concatenate(tips), np.concatenate(xs), np.concatenate(ds),
                 np.concatenate(ps), span_deg)


def anova(loops: Sequence[Loops]) -> tuple[float, float, float, float]:
    """Between-level against within-level (repeat) variance over configurations.

    Returns (F, dof between, dof within, p). The dofs are shrunk by the lag-1 correlation of
    the within-level deviations along the loop (smooth drift between repeats counts as few
    independent values, white noise as many).
    """
    ssb = ssw = dfb = dfw = 0.0
    for lp in loops:
        n_lev, n_rep, k = lp.y.shape
        m = lp.y.mean(axis=1)
        dev = lp.y - m[:, None, :]
        ssb += n_rep * float(((m - m.mean(axis=0)) ** 2).sum())
        ssw += float((dev**2).sum())
        flat = dev.reshape(-1, k)
        num = float((flat[:, 1:] * flat[:, :-1]).sum())
        den = float((flat**2).sum())
        rho = min(max(num / den if den > 0 else 0.0, 0.0), 0.95)
        eff = (1.0 - rho) / (1.0 + rho)
        dfb += (n_lev - 1) * k * eff
        dfw += n_lev * (n_rep - 1) * k * eff
    if ssw <= 0 or dfb <= 0 or dfw <= 0:
        return float("nan"), dfb, dfw, 1.0
    f = (ssb / dfb) / (ssw / dfw)
    return f, dfb, dfw, float(stats.f.sf(f, dfb, dfw))


def contrast_of(lp: Loops) -> FloatArray:
    """The level means of the residual loops about their mean (levels x K)."""
    m = lp.y.mean(axis=1)
    return np.asarray(m - m.mean(axis=0))


def noise_ss(lp: Loops) -> float:
    """Expected sum of squares of the level contrasts from repeat noise alone."""
    n_lev, n_rep, k = lp.y.shape
    dev = lp.y - lp.y.mean(axis=1)[:, None, :]
    var = float((dev**2).sum()) / max(n_lev * (n_rep - 1) * k, 1)
    return (n_lev - 1) * k * var / n_rep + lp.ref_noise_ss


def _slope(lp: Loops, mean_loop: FloatArray) -> FloatArray:
    """Slope of the mean loop against the knob along each branch (runs of one part and
    direction)."""
    g = np.zeros(len(lp.knob))
    # the slope along each branch: runs of points of one part and direction
    edges = np.flatnonzero((np.diff(lp.part) != 0) | (np.diff(lp.dirn) != 0)) + 1
    for run in np.split(np.arange(len(g)), edges):
        if len(run) > 2:
            g[run] = np.gradient(mean_loop[run], lp.knob[run])
    return g


def _design(lp: Loops, mean_loop: FloatArray) -> FloatArray:
    """Effect-model regressors per point: shift along the knob (slope), widening (slope x
    branch, also growing with the bend), a dead zone widening (slope x side: both sides'
    loaded branches move outwards, as more slack makes them; since session 11), a branch
    offset and an offset, per knob/channel."""
    g = _slope(lp, mean_loop)
    load = np.abs(lp.knob)
    side = np.sign(lp.knob)
    cols = []
    for p in np.unique(lp.part):
        z = (lp.part == p).astype(float)
        cols += [z * g, z * g * lp.dirn, z * g * lp.dirn * load, z * g * side, z * lp.dirn,
                 z * lp.dirn * load, z]
    return np.column_stack(cols)


def bend_design(lp: Loops, mean_loop: FloatArray) -> FloatArray:
    """:func:`_design` plus a gain per knob/channel (a residual growing with the knob angle):
    a sheath shape changes the friction along it and with that the loaded branches' tip/knob
    slope, which neither a shift nor a widening takes (the curvature test's model)."""
    gains = [(lp.part == p) * lp.knob for p in np.unique(lp.part)]
    return np.column_stack([_design(lp, mean_loop), *gains])


LAGS_S: tuple[float, ...] = (0.03, 0.1, 0.3)
"""Time constants (s) of the first-order lags whose speed contrasts span the lag model."""


def smooth_along(lp: Loops, loop: FloatArray, length_deg: float) -> FloatArray:
    """``loop`` through a first-order lag of ``length_deg`` of knob travel, run along each
    part's closed path (falling branch from +A, then rising) until periodic: what a lag of
    ``length_deg / speed`` seconds makes of the loop at a constant knob speed."""
    out = loop.copy()
    for p in np.unique(lp.part):
        fall = np.flatnonzero((lp.part == p) & (lp.dirn < 0))
        rise = np.flatnonzero((lp.part == p) & (lp.dirn > 0))
        path = np.concatenate([fall[np.argsort(-lp.knob[fall])], rise[np.argsort(lp.knob[rise])]])
        x = lp.knob[path] * lp.span_deg
        step = np.abs(np.diff(x, append=x[0]))  # the last step closes the loop
        alpha = np.exp(-np.roll(step, 1) / max(length_deg, 1e-9))
        src = loop[path]
        y = float(src[-1])
        for _ in range(3):  # three laps: the start value is forgotten
            ys = np.empty(len(path))
            for k in range(len(path)):
                y = alpha[k] * y + (1.0 - alpha[k]) * float(src[k])
                ys[k] = y
        out[path] = ys
    return out


def lag_design(speeds_deg_s: Sequence[float]) -> Callable[[Loops, FloatArray], FloatArray]:
    """A lag of the measured signal, fitted on the loops of the levels run at
    ``speeds_deg_s``: per knob and lag in :data:`LAGS_S`, the measured mean loop smoothed
    along its path over the fastest level's travel in that time minus over the slowest's
    (exact where the loop has sharp corners, unlike its first-order expansion, slope times
    branch direction); plus a branch offset (what the simulator's fitted viscous term of the
    current already took of the lag)."""
    fast, slow = max(speeds_deg_s), min(speeds_deg_s)

    def design(lp: Loops, mean_loop: FloatArray) -> FloatArray:
        cols = [smooth_along(lp, mean_loop, fast * tau) - smooth_along(lp, mean_loop, slow * tau)
                for tau in LAGS_S]
        out = []
        for p in np.unique(lp.part):
            z = (lp.part == p).astype(float)
            out += [z * c for c in cols] + [z * lp.dirn]
        return np.column_stack(out)

    return design


def loop_shrink(train: Sequence[Loops], held: Loops,
                design: Callable[[Loops, FloatArray], FloatArray] | None = None) -> float:
    """Share of the held-out configuration's level contrast (above repeat noise) that an
    effect model fitted on the training configurations removes."""
    design = design or _design
    c_ho = contrast_of(held)
    excess = float((c_ho**2).sum()) - noise_ss(held)
    if excess <= noise_ss(held) or not train:  # no contrast above the repeats' noise
        return float("nan")
    coef = []
    for lp in train:
        a = design(lp, lp.tip)
        c = contrast_of(lp)
        coef.append(np.array([np.linalg.lstsq(a, c[lv], rcond=None)[0]
                              for lv in range(c.shape[0])]))
    beta = np.mean(coef, axis=0)
    a_ho = design(held, held.tip)
    resid = c_ho - beta @ a_ho.T
    return min(1.0 - (float((resid**2).sum()) - noise_ss(held)) / excess, 1.0)
