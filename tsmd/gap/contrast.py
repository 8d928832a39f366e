"""Effects as differences between matched segments of the data (see :mod:`tsmd.gap.protocol`).

The structural layer leaves 0.6-7.5 deg of base mismatch on a catheter of other physics, more
than coupling, rate dependence or creep move the tip. In matched segments (the same motion under
two conditions) the base mismatch is the same and cancels; what differs between them is the
effect of the condition, whatever the base physics. Each test compares the residual (data minus
the physics simulator, so a difference the simulator itself predicts is no gap) between
condition levels against the spread between repeats of the same level, taken from the same
recording (a one-way analysis of variance whose degrees of freedom are shrunk by the
repeats' correlation along the loop). Its *share* is how much of a held-out configuration's
contrast a small effect model fitted on the other configuration removes.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import stats

from tsmd.gap.data import GapSeries
from tsmd.gap.signature import SIGNATURES, SignatureScore

FloatArray = NDArray[np.float64]
Triple = tuple[FloatArray, FloatArray, FloatArray]
"""One channel of a matched loop: knob angle, residual, measured tip."""

DECIDES: dict[str, str] = {"rate": "rate", "coupling": "coupling", "creep": "drift",
                           "curvature": "curvature"}
"""Protocol test -> the signature it replaces when the recordings carry it (curvature: the
rate and coupling tests' loops compared across configurations)."""

UNMATCHED: frozenset[str] = frozenset({"compliance"})
"""Signatures the protocol has no matched contrast for. Their null (the load shifted in time)
breaks the link between the condition and the knob history, which the base mismatch shares:
on catheters of other physics they beat it without an effect (tendon stretch and sheath
friction both grow with the tension, so no knob motion tells them apart). With the protocol
they are still scored and shown, but not named."""

CONDITIONS: dict[str, str] = {
    "rate": "the same loops at two speeds (matched segments)",
    "coupling": "the same loop with the other knob held at -, 0, + (matched segments)",
    "creep": "tip and current drift in loaded against unloaded dwells",
    "curvature": "the same loops in two sheath configurations (matched segments)",
}


@dataclass
class Loops:
    """One test in one configuration: residual loops sampled at matched knob angles."""

    y: FloatArray  # (levels, reps, K) residual at the matched points
    tip: FloatArray  # (K,) the measured loop, mean over levels and repeats
    knob: FloatArray  # (K,) the knob angle of each point
    dirn: FloatArray  # (K,) +1 rising branch, -1 falling
    part: FloatArray  # (K,) which knob / channel the point belongs to


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
        for grid, sign in grids:
            xs.append(grid / max(float(np.abs(knob_ref).max()), 1e-9))
            ds.append(np.full(len(grid), sign))
            ps.append(np.full(len(grid), float(p)))
    y = np.array([[np.concatenate(ys[(lv, r)]) for r in (0, 1)] for lv in levels])
    return Loops(y, np.concatenate(tips), np.concatenate(xs), np.concatenate(ds),
                 np.concatenate(ps))


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


def _contrast(lp: Loops) -> FloatArray:
    m = lp.y.mean(axis=1)
    return np.asarray(m - m.mean(axis=0))


def _noise_ss(lp: Loops) -> float:
    """Expected sum of squares of the level contrasts from repeat noise alone."""
    n_lev, n_rep, k = lp.y.shape
    dev = lp.y - lp.y.mean(axis=1)[:, None, :]
    var = float((dev**2).sum()) / max(n_lev * (n_rep - 1) * k, 1)
    return (n_lev - 1) * k * var / n_rep


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
    branch, also growing with the bend), a branch offset and an offset, per knob/channel."""
    g = _slope(lp, mean_loop)
    load = np.abs(lp.knob)
    cols = []
    for p in np.unique(lp.part):
        z = (lp.part == p).astype(float)
        cols += [z * g, z * g * lp.dirn, z * g * lp.dirn * load, z * lp.dirn,
                 z * lp.dirn * load, z]
    return np.column_stack(cols)


def lag_design(lp: Loops, mean_loop: FloatArray) -> FloatArray:
    """A lag of the measured signal: its loop delayed along the knob, i.e. widened by the
    slope times the branch direction, per knob; plus a branch offset (what the simulator's
    fitted viscous term of the current already took of the lag)."""
    g = _slope(lp, mean_loop)
    cols = []
    for p in np.unique(lp.part):
        z = (lp.part == p).astype(float)
        cols += [z * g * lp.dirn, z * lp.dirn]
    return np.column_stack(cols)


def loop_shrink(train: Sequence[Loops], held: Loops,
                design: Callable[[Loops, FloatArray], FloatArray] | None = None) -> float:
    """Share of the held-out configuration's level contrast (above repeat noise) that an
    effect model fitted on the training configurations removes."""
    design = design or _design
    c_ho = _contrast(held)
    excess = float((c_ho**2).sum()) - _noise_ss(held)
    if excess <= _noise_ss(held) or not train:  # no contrast above the repeats' noise
        return float("nan")
    coef = []
    for lp in train:
        a = design(lp, lp.tip)
        c = _contrast(lp)
        coef.append(np.array([np.linalg.lstsq(a, c[lv], rcond=None)[0]
                              for lv in range(c.shape[0])]))
    beta = np.mean(coef, axis=0)
    a_ho = design(held, held.tip)
    resid = c_ho - beta @ a_ho.T
    return min(1.0 - (float((resid**2).sum()) - _noise_ss(held)) / excess, 1.0)


@dataclass
class Drift:
    """Per dwell pair (loaded, unloaded) and channel: slope difference and its variance."""

    diff: FloatArray  # (pairs, channels) loaded minus unloaded slope
    var: FloatArray


def dwell_slope(t: FloatArray, y: FloatArray) -> tuple[float, float]:
    """Least-squares slope and its variance, inflated for correlated residuals."""
    tc = t - t.mean()
    sxx = float((tc**2).sum())
    slope = float((tc * (y - y.mean())).sum() / sxx)
    r = y - y.mean() - slope * tc
    rho = float((r[1:] * r[:-1]).sum() / max(float((r**2).sum()), 1e-300))
    rho = min(max(rho, 0.0), 0.95)
    var = float((r**2).sum()) / max(len(r) - 2, 1) / sxx * (1.0 + rho) / (1.0 - rho)
    return slope, var


def drift_stat(drifts: Sequence[Drift]) -> tuple[float, float, float]:
    """Chi-square of the loaded-minus-unloaded slopes; returns (chi2, dof, p)."""
    used = [d.var > 0 for d in drifts]  # a channel that never changes has no slope
    chi = sum(float((d.diff[u] ** 2 / d.var[u]).sum()) for d, u in zip(drifts, used, strict=True))
    dof = float(sum(int(u.sum()) for u in used))
    return chi, dof, float(stats.chi2.sf(chi, dof)) if dof else 1.0


def drift_shrink(train: Sequence[Drift], held: Drift) -> float:
    """Share of the held-out configuration's creep drift (above its noise) predicted by the
    drift per dwell and channel of the training configurations."""
    if not train:
        return float("nan")
    w = 1.0 / np.maximum(np.mean([d.var.mean(axis=0) for d in (*train, held)], axis=0), 1e-300)
    excess = float(((held.diff**2 - held.var) * w).sum())
    if excess <= float((held.var * w).sum()):  # no drift above its noise
        return float("nan")
    pred = np.mean([d.diff for d in train], axis=0)
    resid = float((((held.diff - pred) ** 2 - held.var) * w).sum())
    return min(1.0 - resid / excess, 1.0)


def _z(p: float) -> float:
    return float(np.clip(stats.norm.isf(min(max(p, 1e-300), 1.0 - 1e-16)), -40.0, 40.0))


@dataclass
class TestData:
    """One test's matched windows in one configuration, by (level, repeat)."""

    levels: list[str]
    loops: dict[tuple[str, int], list[Triple | None]]
    dwells: dict[tuple[str, int], tuple[FloatArray, FloatArray]]
    currents: dict[tuple[str, int], list[Triple | None]]
    """The same loops' currents (knob, residual, measured current)."""


def contrast_scores(series: Sequence[GapSeries], residuals: Sequence[FloatArray],
                    n_tried: int, family_alpha: float = 0.05,
                    min_share: float = 0.05) -> list[SignatureScore]:
    """Score every protocol test found in ``series`` (``residuals``: (n, 4) data minus the
    physics simulator, per series). Significant: p below ``family_alpha / n_tried`` and at
    least ``min_share`` of a held-out configuration's contrast reproduced."""
    by_config: dict[str, dict[str, TestData]] = {}
    for s, res in zip(series, residuals, strict=True):
        if s.segment is not None:
            _collect(s, res, by_config.setdefault(s.config, {}))
    out = []
    crit = family_alpha / max(n_tried, 1)
    for test, name in DECIDES.items():
        per_cfg = [d[test] for d in by_config.values() if test in d]
        if test == "curvature":
            loops = [lp for lp in (_across_configs([d[t] for d in by_config.values() if t in d])
                                   for t in ("rate", "coupling")) if lp is not None]
            if len(loops) < 2:
                continue
            p = anova(loops)[3]
            # fitted on one motion's configuration contrast, scored on the other motion's
            shrinks = [loop_shrink([loops[1 - i]], loops[i]) for i in range(2)]
        elif test == "creep":
            drifts = [d for d in (_drift(t) for t in per_cfg) if d.diff.size]
            if not drifts:
                continue
            _, _, p = drift_stat(drifts)
            shrinks = [drift_shrink(drifts[:i] + drifts[i + 1:], drifts[i])
                       for i in range(len(drifts))]
        else:
            found = [loop_contrast(t.loops, t.levels) for t in per_cfg]
            loops = [lp for lp in found if lp is not None]
            if not loops:
                continue
            p = anova(loops)[3]
            shrinks = [loop_shrink(loops[:i] + loops[i + 1:], loops[i])
                       for i in range(len(loops))]
        finite = [x for x in shrinks if np.isfinite(x)]
        share = float(np.mean(finite)) if finite else 0.0
        lo_hi = (min(finite), max(finite)) if finite else (float("nan"), float("nan"))
        title, _ = SIGNATURES[name]
        sig = bool(p < crit and finite and share >= min_share)
        out.append(SignatureScore(name, title, CONDITIONS[test], share, lo_hi, sig, share, 0.0,
                                  _z(p)))
    return out


def _across_configs(per_cfg: Sequence[TestData]) -> Loops | None:
    """One test's loops with the configurations as the levels (all its levels side by side),
    each loop's mean removed: an offset between sessions (tracker registration) is no shape."""
    if len(per_cfg) < 2:
        return None
    found = [loop_contrast(t.loops, t.levels) for t in per_cfg]
    loops = [lp for lp in found if lp is not None]
    if len(loops) < 2 or len({lp.y.shape for lp in loops}) > 1:
        return None
    n_lev, n_rep, k = loops[0].y.shape
    y = np.array([lp.y.transpose(1, 0, 2).reshape(n_rep, n_lev * k) for lp in loops])
    part = np.tile(loops[0].part, n_lev)
    for p in np.unique(part):
        for lv in range(n_lev):
            cols = np.zeros(n_lev * k, dtype=bool)
            cols[lv * k:(lv + 1) * k] = loops[0].part == p
            y[:, :, cols] -= y[:, :, cols].mean(axis=2, keepdims=True)
    first = loops[0]
    return Loops(y, np.tile(np.mean([lp.tip for lp in loops], axis=0), n_lev),
                 np.tile(first.knob, n_lev), np.tile(first.dirn, n_lev), part)


def _collect(s: GapSeries, res: FloatArray, tests: dict[str, TestData]) -> None:
    """File one series' matched windows under their test (in place)."""
    assert s.segment is not None
    for i, seg in enumerate(s.segments):
        rows = np.flatnonzero(s.segment == i)
        if len(rows) < 5:
            continue
        data = tests.setdefault(seg.test, TestData([], {}, {}, {}))
        if seg.level not in data.levels:
            data.levels.append(seg.level)
        key = (seg.level, seg.rep)
        if seg.test == "creep":
            data.dwells[key] = (s.t_s[rows], res[rows])
            continue
        knobs = (0, 1) if seg.knob < 0 else (seg.knob,)
        windows: list[Triple | None] = [(s.knob_deg[rows, j], res[rows, j], s.tip_deg[rows, j])
                                        for j in knobs]
        if seg.knob >= 0:  # the knobs' sub-tests share the levels: one part per knob
            parts = data.loops.setdefault(key, [None, None])
            parts[seg.knob] = windows[0]
        else:
            data.loops.setdefault(key, []).extend(windows)
            data.currents.setdefault(key, []).extend(
                (s.knob_deg[rows, j], res[rows, 2 + j], s.current_A[rows, j]) for j in knobs)


def _drift(data: TestData) -> Drift:
    """Loaded-minus-unloaded dwell slopes per repeat and channel."""
    diffs, vars_ = [], []
    for rep in sorted({r for _, r in data.dwells}):
        loaded, unloaded = data.dwells.get(("loaded", rep)), data.dwells.get(("unloaded", rep))
        if loaded is None or unloaded is None:
            continue
        (tl, yl), (tu, yu) = loaded, unloaded
        row_d, row_v = [], []
        for ch in range(yl.shape[1]):
            sl, vl = dwell_slope(tl, yl[:, ch])
            su, vu = dwell_slope(tu, yu[:, ch])
            row_d.append(sl - su)
            row_v.append(vl + vu)
        diffs.append(row_d)
        vars_.append(row_v)
    return Drift(np.array(diffs, dtype=float).reshape(len(diffs), -1),
                 np.array(vars_, dtype=float).reshape(len(vars_), -1))


def lag_share(series: Sequence[GapSeries],
              residuals: Sequence[FloatArray]) -> tuple[float, float, float] | None:
    """Share of the rate test's current contrast (fast against slow loops) that a lag of the
    current explains, fitted on one configuration and scored on the other (mean, lowest,
    highest over the held-out configurations); None without such a contrast."""
    by_config: dict[str, dict[str, TestData]] = {}
    for s, res in zip(series, residuals, strict=True):
        if s.segment is not None:
            _collect(s, res, by_config.setdefault(s.config, {}))
    found = [loop_contrast(d["rate"].currents, d["rate"].levels)
             for d in by_config.values() if "rate" in d]
    loops = [lp for lp in found if lp is not None]
    shrinks = [loop_shrink(loops[:i] + loops[i + 1:], loops[i], lag_design)
               for i in range(len(loops))]
    finite = [x for x in shrinks if np.isfinite(x)]
    return (float(np.mean(finite)), min(finite), max(finite)) if finite else None


def segments_present(series: Sequence[GapSeries]) -> bool:
    """True when any recording carries the matched-condition protocol."""
    return any(s.segment is not None for s in series)
