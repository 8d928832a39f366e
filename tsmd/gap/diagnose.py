"""The whole diagnosis: fit the base simulator, locate the gap, rank candidates, measure the shrink.

Scores are in noise units: per channel (tip1, tip2, cur1, cur2) squared residuals are divided by
that channel's white-noise variance, estimated from the measurement itself (second differences).
Summed over a block this is about the number of values if the simulator matched to within noise;
what exceeds it is the *excess gap*. A candidate's score is the share of the held-out excess gap
it removes, with a bootstrap confidence interval over held-out time blocks.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.candidates import catalogue
from tsmd.gap.data import GapSeries, Split, make_split
from tsmd.gap.model import (
    CHANNELS,
    Active,
    Candidate,
    Evaluator,
    ParamSpec,
    Prediction,
    View,
    build_views,
    fit_base,
    fit_candidate,
)
from tsmd.gap.simulate import PlantFactory
from tsmd.gap.stats import bootstrap_ratio_ci, noise_variance, pooled_ljung_box, ptpe, rmse
from tsmd.gap.where import BinRow, breakdown, label_knob


@dataclass(frozen=True)
class GapConfig:
    """Settings of one diagnosis (defaults are what `tsmd gap` uses)."""

    fit_specs: tuple[ParamSpec, ...] = ()
    holdout: float | tuple[str, ...] = 0.3
    block_s: float | None = None
    fit_rate_hz: float = 25.0
    base_evals: int = 30
    candidate_evals: int = 10
    seed: int = 0
    n_boot: int = 2000
    ci_level: float = 0.9
    min_share: float = 0.05
    explained_share: float = 0.5
    gap_floor: float = 0.1
    max_combined: int = 3
    candidates: tuple[str, ...] | None = None


@dataclass
class CandidateScore:
    name: str
    title: str
    physics: str
    params: dict[str, float]
    share: float
    ci: tuple[float, float]
    significant: bool
    train_cost_drop: float
    ljung_box_q: dict[str, float]
    metrics: dict[str, float]


@dataclass
class GapResult:
    """Everything the report shows; :meth:`to_json` gives the same figures as plain data."""

    verdict: str
    summary: str
    split: str
    base_params: dict[str, float]
    noise_std: dict[str, float]
    gap_ratio: tuple[float, float, float]
    before: dict[str, float]
    after_top: dict[str, float] | None
    after_combined: dict[str, float] | None
    top: list[str]
    combined: list[str]
    combined_share: tuple[float, float, float] | None
    candidates: list[CandidateScore]
    where_shares: dict[str, dict[str, float]]
    where_bins: dict[str, list[BinRow]]
    ljung_box_base: dict[str, float]
    timing_s: dict[str, float]
    rows: dict[str, int]
    plot_data: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> dict[str, Any]:
        return {
            "verdict": self.verdict, "summary": self.summary, "split": self.split,
            "base_params": self.base_params, "noise_std": self.noise_std,
            "gap_ratio": {"point": self.gap_ratio[0], "ci": list(self.gap_ratio[1:])},
            "before": self.before, "after_top": self.after_top,
            "after_combined": self.after_combined, "top": self.top, "combined": self.combined,
            "combined_share": (None if self.combined_share is None else
                               {"point": self.combined_share[0],
                                "ci": list(self.combined_share[1:])}),
            "candidates": [{
                "name": c.name, "title": c.title, "physics": c.physics, "params": c.params,
                "share": c.share, "ci": list(c.ci), "significant": c.significant,
                "train_cost_drop": c.train_cost_drop, "ljung_box_q": c.ljung_box_q,
                "metrics": c.metrics} for c in self.candidates],
            "where": {
                group: {"shares": self.where_shares[group],
                        "bins": [vars(b) for b in self.where_bins[group]]}
                for group in self.where_shares},
            "ljung_box_base": self.ljung_box_base, "timing_s": self.timing_s, "rows": self.rows,
        }


def _strides(series: Sequence[GapSeries], fit_rate_hz: float) -> list[int]:
    out = []
    for s in series:
        fs = 1.0 / float(np.median(np.diff(s.t_s)))
        out.append(max(round(fs / fit_rate_hz), 1))
    return out


def _noise_var(series: Sequence[GapSeries], split: Split) -> NDArray[np.float64]:
    var = np.zeros(4)
    for c in range(4):
        parts = []
        for s, ho in zip(series, split.held_out, strict=True):
            y = s.tip_deg[:, c] if c < 2 else s.current_A[:, c - 2]
            parts.append(y[~ho])
        var[c] = float(np.median([noise_variance(p) for p in parts if len(p) > 10]))
    return var


def _block_costs(views: Sequence[View], pred: Prediction, split: Split,
                 noise_var: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per held-out block: weighted squared residual and number of values (the noise level)."""
    costs, counts = [], []
    for i, mask_full in split.test_blocks():
        v = views[i]
        m = mask_full[v.rows]
        r = (pred.values[i] - v.measured)[m]
        costs.append(float(np.sum(r * r / noise_var)))
        counts.append(float(r.size))
    return np.array(costs), np.array(counts)


def _metrics(views: Sequence[View], pred: Prediction) -> dict[str, float]:
    """Held-out RMSE and PTPE of tip (deg) and RMSE of current (A), per knob."""
    r = np.vstack([(p - v.measured)[v.test] for v, p in zip(views, pred.values, strict=True)])
    return {"tip1_rmse_deg": rmse(r[:, 0]), "tip2_rmse_deg": rmse(r[:, 1]),
            "tip1_ptpe_deg": ptpe(r[:, 0]), "tip2_ptpe_deg": ptpe(r[:, 1]),
            "cur1_rmse_A": rmse(r[:, 2]), "cur2_rmse_A": rmse(r[:, 3])}


def _whiteness(views: Sequence[View], pred: Prediction) -> dict[str, float]:
    out = {}
    for c, name in enumerate(CHANNELS):
        segs = [(p - v.measured)[v.test, c] for v, p in zip(views, pred.values, strict=True)]
        out[name] = pooled_ljung_box(segs)[0]
    return out


def _where(views: Sequence[View], pred: Prediction) -> tuple[dict[str, dict[str, float]],
                                                             dict[str, list[BinRow]]]:
    vel = np.concatenate([np.abs(v.vel_deg_s[v.test]).ravel() for v in views])
    edges = np.percentile(vel, [0, 25, 50, 75, 100]) if vel.size else np.array([0.0, 1.0])
    edges = np.unique(edges)
    if len(edges) < 2:
        edges = np.array([0.0, 1.0])
    resid: dict[str, list[NDArray[np.float64]]] = {"tip": [], "current": []}
    labels: dict[str, list[Any]] = {"tip": [], "current": []}
    for v, p in zip(views, pred.values, strict=True):
        if not v.test.any():
            continue
        assert v.base_tip is not None
        r = p - v.measured
        run_s = v.series.duration_s
        for j in range(2):
            lab = label_knob(v.t_s, v.knob_deg[:, j], v.knob_deg[:, 1 - j], v.vel_deg_s[:, j],
                             v.base_tip[:, j], v.t_s - v.series.t_s[0], run_s, edges)
            sub = type(lab)({k: a[v.test] for k, a in lab.labels.items()})
            resid["tip"].append(r[v.test, j])
            labels["tip"].append(sub)
            resid["current"].append(r[v.test, 2 + j])
            labels["current"].append(sub)
    shares, bins = {}, {}
    for group in ("tip", "current"):
        shares[group], bins[group] = breakdown(resid[group], labels[group])
    return shares, bins


def diagnose(series: Sequence[GapSeries], factory: PlantFactory,
             plant_params: dict[str, float], config: GapConfig | None = None) -> GapResult:
    """Run the five stages on recordings already checked by ``series_from_recording``."""
    cfg = config or GapConfig()
    clock = time.perf_counter
    timing: dict[str, float] = {}
    t0 = clock()
    holdout = cfg.holdout if isinstance(cfg.holdout, float) else list(cfg.holdout)
    split = make_split(series, holdout, cfg.block_s)
    strides = _strides(series, cfg.fit_rate_hz)
    fit_views = build_views(series, split, strides, "fit")
    eval_views = build_views(series, split, strides, "eval")
    noise_var = _noise_var(series, split)
    v0 = np.maximum(0.05 * np.percentile(
        np.abs(np.vstack([v.vel_deg_s for v in fit_views])), 95, axis=0), 0.1)
    ev = Evaluator(factory, dict(plant_params), noise_var, v0)

    # (2) base fit on training rows of the thinned grid
    base_params, base_cost = fit_base(ev, fit_views, cfg.fit_specs, cfg.base_evals)
    base_fit = ev.predict(fit_views, [])
    timing["base_fit"] = clock() - t0

    # (1) replay at full rate on held-out rows, with the linear terms from the fit
    t1 = clock()
    base_eval = ev.predict(eval_views, [], coefs=base_fit.coefs)
    base_blocks, counts = _block_costs(eval_views, base_eval, split, noise_var)
    excess = base_blocks - counts
    gap_ratio = bootstrap_ratio_ci(base_blocks, counts, cfg.seed, cfg.n_boot, cfg.ci_level)
    timing["replay"] = clock() - t1

    # (3) where
    t2 = clock()
    where_shares, where_bins = _where(eval_views, base_eval)
    timing["where"] = clock() - t2

    # (4) which
    t3 = clock()
    torque_ref = np.percentile(np.abs(np.vstack(
        [v.base_torque for v in fit_views if v.base_torque is not None])), 95, axis=0)
    cands = [c for c in catalogue(torque_ref)
             if cfg.candidates is None or c.name in cfg.candidates]
    gap_present = float(excess.sum()) > cfg.gap_floor * float(base_blocks.sum())
    scores: list[CandidateScore] = []
    fitted: dict[str, tuple[Candidate, NDArray[np.float64]]] = {}
    preds: dict[str, Prediction] = {}
    for cand in cands:
        theta, cost = fit_candidate(ev, fit_views, cand, max_evals=cfg.candidate_evals)
        active: Active = [(cand, theta)]
        coefs = ev.predict(fit_views, active).coefs
        pred = ev.predict(eval_views, active, coefs=coefs)
        blocks, _ = _block_costs(eval_views, pred, split, noise_var)
        share, lo, hi = bootstrap_ratio_ci(base_blocks - blocks, excess, cfg.seed, cfg.n_boot,
                                           cfg.ci_level)
        significant = bool(gap_present and lo > 0 and share >= cfg.min_share)
        scores.append(CandidateScore(
            cand.name, cand.title, cand.physics,
            {n: float(x) for n, x in zip(cand.param_names, theta, strict=True)},
            share, (lo, hi), significant,
            (base_cost - cost) / base_cost if base_cost > 0 else 0.0,
            _whiteness(eval_views, pred), _metrics(eval_views, pred)))
        fitted[cand.name] = (cand, theta)
        preds[cand.name] = pred
    scores.sort(key=lambda c: -c.share)
    timing["candidates"] = clock() - t3

    # (5) how far: top effect and the significant top effects together
    t4 = clock()
    sig = [c for c in scores if c.significant]
    top = [sig[0].name] if sig else []
    combined = [c.name for c in sig[: cfg.max_combined]]
    after_top = _metrics(eval_views, preds[top[0]]) if top else None
    after_combined = None
    combined_share = None
    if len(combined) > 1:
        active = [fitted[n] for n in combined]
        coefs = ev.predict(fit_views, active).coefs
        pred = ev.predict(eval_views, active, coefs=coefs)
        blocks, _ = _block_costs(eval_views, pred, split, noise_var)
        combined_share = bootstrap_ratio_ci(base_blocks - blocks, excess, cfg.seed, cfg.n_boot,
                                            cfg.ci_level)
        after_combined = _metrics(eval_views, pred)
        preds["+".join(combined)] = pred
    elif top:
        combined_share = (sig[0].share, *sig[0].ci)
        after_combined = after_top
    timing["how_far"] = clock() - t4

    verdict, summary = _verdict(cfg, gap_present, gap_ratio, sig, combined, combined_share)
    timing["total"] = clock() - t0
    result = GapResult(
        verdict=verdict, summary=summary, split=split.description, base_params=base_params,
        noise_std={n: float(np.sqrt(v)) for n, v in zip(CHANNELS, noise_var, strict=True)},
        gap_ratio=gap_ratio, before=_metrics(eval_views, base_eval), after_top=after_top,
        after_combined=after_combined, top=top, combined=combined,
        combined_share=combined_share, candidates=scores, where_shares=where_shares,
        where_bins=where_bins, ljung_box_base=_whiteness(eval_views, base_eval),
        timing_s=timing,
        rows={"total": int(sum(len(s) for s in series)),
              "held_out": int(sum(int(h.sum()) for h in split.held_out)),
              "simulated": int(ev.sim_rows), "model_evaluations": int(ev.evaluations),
              "fit_stride_max": int(max(strides))})
    result.plot_data = {"views": eval_views, "base": base_eval,
                        "top": preds[top[0]] if top else None,
                        "combined": preds.get("+".join(combined)) if len(combined) > 1 else None}
    return result


def _verdict(cfg: GapConfig, gap_present: bool, gap_ratio: tuple[float, float, float],
             sig: list[CandidateScore], combined: list[str],
             combined_share: tuple[float, float, float] | None) -> tuple[str, str]:
    ratio = gap_ratio[0]
    if not gap_present:
        return "none significant", (
            f"The simulator matches the held-out data to within the measurement noise "
            f"(residual/noise = {ratio:.2f}); no candidate effect is needed.")
    if not sig:
        return "unexplained", (
            f"The held-out residual is {ratio:.1f}x the noise level, but no candidate effect "
            f"reduces it significantly: the gap is unexplained by the catalogue.")
    best = combined_share[0] if combined_share is not None else sig[0].share
    names = " + ".join(combined)
    if best < cfg.explained_share:
        return "unexplained", (
            f"Best candidates ({names}) remove only {best:.0%} of the excess held-out gap "
            f"(residual/noise = {ratio:.1f}x); most of the gap is unexplained.")
    return f"identified: {sig[0].name}", (
        f"Top effect: {sig[0].title} removes {sig[0].share:.0%} "
        f"(90% CI {sig[0].ci[0]:.0%}..{sig[0].ci[1]:.0%}) of the excess held-out gap; "
        f"with {names}: {best:.0%}.")
