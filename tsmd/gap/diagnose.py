"""The whole diagnosis: fit the base simulator, locate the gap, rank candidates, measure the shrink.

Scores are in noise units: per channel (tip1, tip2, cur1, cur2) squared residuals are divided by
that channel's white-noise variance, estimated from the measurement itself (second differences).
Summed over a block this is about the number of values if the simulator matched to within noise;
what exceeds it is the *excess gap*. A candidate's score is the share of the held-out excess gap
it removes, with a bootstrap confidence interval over held-out time blocks.
"""

from __future__ import annotations

import copy
import time
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.candidates import catalogue
from tsmd.gap.data import GapSeries, Split, fit_windows, make_split
from tsmd.gap.fit import fit_base, fit_candidate, get_param, joint_refine, polish_base
from tsmd.gap.model import CHANNELS, Active, Candidate, Evaluator, Prediction, View, build_views
from tsmd.gap.result import CandidateScore, GapConfig, GapResult
from tsmd.gap.simulate import PlantFactory
from tsmd.gap.stats import bootstrap_ratio_ci, noise_variance, pooled_ljung_box, ptpe, rmse
from tsmd.gap.structure import signature_stage
from tsmd.gap.where import BinRow, breakdown, label_knob


def _strides(series: Sequence[GapSeries], max_rows: int) -> list[int]:
    """One row stride for all series so that at most about ``max_rows`` rows are simulated."""
    total = sum(len(s) for s in series)
    return [max(-(-total // max_rows), 1)] * len(series)


def _noise_var(series: Sequence[GapSeries], split: Split) -> NDArray[np.float64]:
    var = np.zeros(4)
    for c in range(4):
        parts = []
        for s, ho in zip(series, split.held_out, strict=True):
            y = s.tip_deg[:, c] if c < 2 else s.current_A[:, c - 2]
            if s.channel_valid[c]:
                parts.append(y[~ho])
        found = [noise_variance(p) for p in parts if len(p) > 10]
        var[c] = float(np.median(found)) if found else 1.0
    return var


def _block_costs(views: Sequence[View], pred: Prediction, split: Split,
                 noise_var: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per held-out block: weighted squared residual and number of values (the noise level)."""
    costs, counts = [], []
    for i, mask_full in split.test_blocks():
        v = views[i]
        m = mask_full[v.rows]
        r = (pred.values[i] - v.measured)[m] * v.valid
        costs.append(float(np.sum(r * r / noise_var)))
        counts.append(float(m.sum() * v.valid.sum()))
    return np.array(costs), np.array(counts)


def _metrics(views: Sequence[View], pred: Prediction) -> dict[str, float]:
    """Held-out RMSE and PTPE of tip (deg) and RMSE of current (A), per knob."""
    r = np.vstack([np.where(v.valid, p - v.measured, np.nan)[v.test]
                   for v, p in zip(views, pred.values, strict=True)])
    return {"tip1_rmse_deg": rmse(r[:, 0]), "tip2_rmse_deg": rmse(r[:, 1]),
            "tip1_ptpe_deg": ptpe(r[:, 0]), "tip2_ptpe_deg": ptpe(r[:, 1]),
            "cur1_rmse_A": rmse(r[:, 2]), "cur2_rmse_A": rmse(r[:, 3])}


def _whiteness(views: Sequence[View], pred: Prediction) -> dict[str, float]:
    out = {}
    for c, name in enumerate(CHANNELS):
        segs = [(p - v.measured)[v.test, c] for v, p in zip(views, pred.values, strict=True)
                if v.valid[c]]
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
            if not (v.valid[j] or v.valid[2 + j]):
                continue
            lab = label_knob(v.t_s, v.knob_deg[:, j], v.knob_deg[:, 1 - j], v.vel_deg_s[:, j],
                             v.base_tip[:, j], v.t_s - v.series.t_s[0], run_s, edges)
            sub = type(lab)({k: a[v.test] for k, a in lab.labels.items()})
            for group, c in (("tip", j), ("current", 2 + j)):
                if v.valid[c]:
                    resid[group].append(r[v.test, c])
                    labels[group].append(sub)
    shares, bins = {}, {}
    for group in ("tip", "current"):
        shares[group], bins[group] = breakdown(resid[group], labels[group])
    return shares, bins


def _use(ev: Evaluator, params: dict[str, Any]) -> None:
    """Switch the evaluator to other plant parameters (drops the cached base simulation)."""
    ev.plant_params = copy.deepcopy(params)
    ev._base_cache.clear()


def is_significant(gain_blocks: NDArray[np.float64], excess_blocks: NDArray[np.float64],
                   n_tried: int, cfg: GapConfig) -> bool:
    """Whether a candidate's held-out gain (per block) is more than chance.

    Several candidates are tried, so each must clear its one-sided bootstrap lower bound at
    ``family_alpha / n_tried`` (Bonferroni): data without an effect then raise a false alarm
    with probability of about ``family_alpha`` at most, not that much per candidate. It must
    also remove at least ``min_share`` of the excess gap.
    """
    share, strict_lo, _ = bootstrap_ratio_ci(gain_blocks, excess_blocks, cfg.seed, cfg.n_boot,
                                             1.0 - 2.0 * cfg.family_alpha / max(n_tried, 1))
    return bool(strict_lo > 0 and share >= cfg.min_share)


def _score(ev: Evaluator, cand: Candidate, theta: NDArray[np.float64], cost: float,
           base_cost: float, fit_views: Sequence[View], rank_views: Sequence[View], split: Split,
           noise_var: NDArray[np.float64], base_blocks: NDArray[np.float64],
           excess: NDArray[np.float64], gap_present: bool, cfg: GapConfig,
           stage: str, n_tried: int) -> CandidateScore:
    """Held-out score of one fitted candidate (with the evaluator's current plant parameters)."""
    active: Active = [(cand, theta)]
    coefs = ev.predict(fit_views, active).coefs
    pred = ev.predict(rank_views, active, coefs=coefs)
    blocks, _ = _block_costs(rank_views, pred, split, noise_var)
    share, lo, hi = bootstrap_ratio_ci(base_blocks - blocks, excess, cfg.seed, cfg.n_boot,
                                       cfg.ci_level)
    return CandidateScore(
        cand.name, cand.title, cand.physics,
        {n: float(x) for n, x in zip(cand.param_names, theta, strict=True)},
        share, (lo, hi),
        gap_present and is_significant(base_blocks - blocks, excess, n_tried, cfg),
        (base_cost - cost) / base_cost if base_cost > 0 else 0.0,
        _whiteness(rank_views, pred), _metrics(rank_views, pred), stage)


def diagnose(series: Sequence[GapSeries], factory: PlantFactory,
             plant_params: dict[str, Any], config: GapConfig | None = None) -> GapResult:
    """Run the five stages on recordings already checked by ``series_from_recording``."""
    cfg = config or GapConfig()
    clock = time.perf_counter
    timing: dict[str, float] = {}
    t0 = clock()
    holdout = cfg.holdout if isinstance(cfg.holdout, float) else list(cfg.holdout)
    split = make_split(series, holdout, cfg.block_s)
    strides = _strides(series, cfg.fit_max_rows)
    n_held = sum(int(h.sum()) for h in split.held_out)
    rank_stride = [max(-(-n_held // cfg.rank_max_rows), 1)] * len(series)
    signature = cfg.method == "signature"
    win_series, win_split = fit_windows(series, split, cfg.fit_window_s, cfg.fit_windows)
    # a long recording is fitted on windows; with the signature method also on a smaller
    # budget (the layer takes what a longer fit would remove); short ones as they always were
    reduced = signature and win_split is not split
    fit_rows = min(cfg.fit_max_rows, cfg.signature_fit_rows) if reduced else cfg.fit_max_rows
    fit_views = build_views(win_series, win_split, _strides(win_series, fit_rows), "fit")
    final_stride = [max(-(-n_held // cfg.final_max_rows), 1)] * len(series)
    final_views = build_views(series, split, strides, "eval", final_stride)
    # the signature method ranks on its own grid: its ranking replay is the final one
    rank_views = (final_views if signature
                  else build_views(series, split, strides, "eval", rank_stride))
    noise_var = _noise_var(series, split)
    v0 = np.maximum(0.02 * np.percentile(
        np.abs(np.vstack([v.vel_deg_s for v in fit_views])), 95, axis=0), 0.1)
    ev = Evaluator(factory, copy.deepcopy(plant_params), noise_var, v0)

    # (2) base fit on training rows of the thinned grid
    base_evals, polish_evals = cfg.signature_fit_evals if reduced else (cfg.base_evals,
                                                                        cfg.polish_evals)
    fit_base(ev, fit_views, cfg.fit_specs, min(base_evals, cfg.base_evals))
    coarse_params, _ = polish_base(ev, fit_views, cfg.fit_specs,
                                   min(polish_evals, cfg.polish_evals))
    if reduced:  # the refinement is the candidate method's control, not needed here
        base_params, base_cost = coarse_params, float("nan")
    else:
        base_params, _, base_cost = joint_refine(ev, fit_views, cfg.fit_specs, None,
                                                 np.zeros(0), coarse_params, cfg.refine_evals, 0)
    _use(ev, base_params)
    base_fit = ev.predict(fit_views, [])
    timing["base_fit"] = clock() - t0

    # (1) replay every held-out row, with the linear terms from the fit
    t1 = clock()
    base_final = ev.predict(final_views, [], coefs=base_fit.coefs)
    base_rank = (base_final if signature
                 else ev.predict(rank_views, [], coefs=base_fit.coefs))
    base_blocks, counts = _block_costs(rank_views, base_rank, split, noise_var)
    excess = base_blocks - counts
    gap_ratio = bootstrap_ratio_ci(base_blocks, counts, cfg.seed, cfg.n_boot, cfg.ci_level)
    timing["replay"] = clock() - t1

    # (3) where
    t2 = clock()
    where_shares, where_bins = _where(final_views, base_final)
    timing["where"] = clock() - t2

    if signature:
        result = signature_stage(series, split, ev, base_fit, strides, noise_var, cfg)
        result.before = _metrics(final_views, base_final)
        result.where_shares, result.where_bins = where_shares, where_bins
        result.ljung_box_base = _whiteness(rank_views, base_rank)
        result.base_params = base_params
        result.fitted_params = {sp.name: float(get_param(base_params, sp.name) or 0.0)
                                for sp in cfg.fit_specs if "+" not in sp.name}
        result.split = split.description
        timing.update(result.timing_s)
        timing["total"] = clock() - t0
        result.timing_s = timing
        result.rows.update({"total": int(sum(len(s) for s in series)), "held_out": n_held,
                            "simulated": int(ev.sim_rows),
                            "model_evaluations": int(ev.evaluations),
                            "fit_stride": int(strides[0])})
        result.plot_data = {"views": final_views, "base": base_final, "top": None,
                            "combined": None}
        return result

    # (4) which
    t3 = clock()
    torque_ref = np.percentile(np.abs(np.vstack(
        [v.base_torque for v in fit_views if v.base_torque is not None])), 95, axis=0)
    cands = [c for c in catalogue(torque_ref)
             if cfg.candidates is None or c.name in cfg.candidates]
    gap_present = float(excess.sum()) > cfg.gap_floor * float(base_blocks.sum())
    scores: list[CandidateScore] = []
    fitted: dict[str, tuple[Candidate, NDArray[np.float64], dict[str, Any]]] = {}
    for cand in cands:
        theta, cost = fit_candidate(ev, fit_views, cand,
                                    max_evals=cfg.candidate_evals * max(len(cand.param_names), 1))
        scores.append(_score(ev, cand, theta, cost, base_cost, fit_views, rank_views, split,
                             noise_var, base_blocks, excess, gap_present, cfg, "screen",
                             len(cands)))
        fitted[cand.name] = (cand, theta, base_params)
    scores.sort(key=lambda c: -c.share)
    timing["candidates"] = clock() - t3

    # (4b) the best screened candidates again, fitted jointly with the base parameters
    t3b = clock()
    if gap_present and cfg.fit_specs and cfg.joint_top > 0:
        joint = []
        for sc in scores[: cfg.joint_top]:
            cand = fitted[sc.name][0]
            params, theta, cost = joint_refine(
                ev, fit_views, cfg.fit_specs, cand, fitted[sc.name][1], coarse_params,
                cfg.refine_evals, cfg.candidate_evals)
            joint.append(_score(ev, cand, theta, cost, base_cost, fit_views, rank_views, split,
                                noise_var, base_blocks, excess, gap_present, cfg, "joint",
                                len(cands)))
            fitted[sc.name] = (cand, theta, params)
        _use(ev, base_params)
        joint.sort(key=lambda c: -c.share)
        names = {c.name for c in joint}
        scores = joint + [c for c in scores if c.name not in names]
    timing["joint"] = clock() - t3b

    # (5) how far, on every held-out row: top effect and the significant top effects together
    t4 = clock()
    sig = [c for c in scores if c.significant]
    top = [sig[0].name] if sig else []
    combined = [c.name for c in sig[: cfg.max_combined]]
    after_top = after_combined = None
    combined_share = None
    top_pred = comb_pred = None
    if top:
        cand, theta, params = fitted[top[0]]
        _use(ev, params)
        active = [(cand, theta)]
        top_pred = ev.predict(final_views, active, coefs=ev.predict(fit_views, active).coefs)
        after_top = after_combined = _metrics(final_views, top_pred)
        combined_share = (sig[0].share, *sig[0].ci)
    if len(combined) > 1:
        _use(ev, fitted[combined[0]][2])
        active = [fitted[n][:2] for n in combined]
        coefs = ev.predict(fit_views, active).coefs
        comb_rank = ev.predict(rank_views, active, coefs=coefs)
        blocks, _ = _block_costs(rank_views, comb_rank, split, noise_var)
        combined_share = bootstrap_ratio_ci(base_blocks - blocks, excess, cfg.seed, cfg.n_boot,
                                            cfg.ci_level)
        comb_pred = ev.predict(final_views, active, coefs=coefs)
        after_combined = _metrics(final_views, comb_pred)
    timing["how_far"] = clock() - t4

    verdict, summary = _verdict(cfg, gap_present, gap_ratio, sig, combined, combined_share)
    timing["total"] = clock() - t0
    result = GapResult(
        verdict=verdict, summary=summary, split=split.description, base_params=base_params,
        fitted_params={sp.name: float(get_param(base_params, sp.name) or 0.0)
                       for sp in cfg.fit_specs if "+" not in sp.name},
        noise_std={n: float(np.sqrt(v)) for n, v in zip(CHANNELS, noise_var, strict=True)},
        gap_ratio=gap_ratio, before=_metrics(final_views, base_final), after_top=after_top,
        after_combined=after_combined, top=top, combined=combined,
        combined_share=combined_share, candidates=scores, where_shares=where_shares,
        where_bins=where_bins, ljung_box_base=_whiteness(rank_views, base_rank),
        timing_s=timing,
        rows={"total": int(sum(len(s) for s in series)), "held_out": n_held,
              "held_out_ranked": int(sum(int(v.test.sum()) for v in rank_views)),
              "simulated": int(ev.sim_rows), "model_evaluations": int(ev.evaluations),
              "fit_stride": int(strides[0])})
    result.plot_data = {"views": final_views, "base": base_final, "top": top_pred,
                        "combined": comb_pred}
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
    best = max(sig[0].share, combined_share[0] if combined_share is not None else 0.0)
    names = " + ".join(combined) if best > sig[0].share else sig[0].name
    if best < cfg.explained_share:
        return "unexplained", (
            f"Best candidates ({names}) remove only {best:.0%} of the excess held-out gap "
            f"(residual/noise = {ratio:.1f}x); most of the gap is unexplained.")
    return f"identified: {sig[0].name}", (
        f"Top effect: {sig[0].title} removes {sig[0].share:.0%} "
        f"(90% CI {sig[0].ci[0]:.0%}..{sig[0].ci[1]:.0%}) of the excess held-out gap; "
        f"with {names}: {best:.0%}.")
