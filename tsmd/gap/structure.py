"""The signature method's stage of a diagnosis: base mismatch, then the effect on top of it."""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.compliance import compliance_score
from tsmd.gap.contrast import (
    DECIDES,
    LOOP_TESTS,
    UNMATCHED,
    contrast_scores,
    segments_present,
)
from tsmd.gap.data import GapSeries, Split
from tsmd.gap.layer import heldout_metrics, stack_views
from tsmd.gap.model import CHANNELS, Evaluator, Prediction, View, build_views
from tsmd.gap.result import CandidateScore, GapConfig, GapResult
from tsmd.gap.sensor import lag_share
from tsmd.gap.signature import SignatureScore, score_signatures
from tsmd.gap.simulate import smooth_velocity


def signature_stage(series: Sequence[GapSeries], split: Split, ev: Evaluator,
                     base_fit: Prediction, strides: Sequence[int], noise_var: NDArray[np.float64],
                     cfg: GapConfig) -> GapResult:
    """Structural layer + condition signatures on a thinned grid (every row's state kept)."""
    t0 = time.perf_counter()
    total = sum(len(s) for s in series)
    sig_stride = [max(-(-total // cfg.sig_max_rows), 1)] * len(series)
    views = build_views(series, split, sig_stride, "fit")
    phys = ev.predict(views, [], coefs=base_fit.coefs)
    d = stack_views(views, [s.config for s in series])
    sres = score_signatures(d, noise_var, np.vstack(phys.values), seed=cfg.seed,
                            n_surrogates=cfg.n_surrogates, n_boot=cfg.n_boot,
                            ci_level=cfg.ci_level, family_alpha=cfg.family_alpha,
                            min_share=cfg.min_share)
    matched = segments_present(series)
    if matched:
        # matched segments decide the effects they test: their contrast cancels the base
        # mismatch, which the signatures of the same effects compete with
        residuals = _residuals(series, split, ev, base_fit)
        found = contrast_scores(series, residuals, len(sres.scores), cfg.family_alpha,
                                cfg.min_share, float(np.sqrt(np.mean(noise_var[:2]))),
                                float(np.sqrt(np.mean(noise_var[2:]))), cfg.product_reference)
        ref = cfg.product_reference
        sheet = (ref.compliance if ref is not None and ref.compliance is not None
                 else cfg.compliance_reference)
        if sheet is not None:
            stretch = compliance_score(series, sheet, len(sres.scores), cfg.family_alpha,
                                       cfg.min_share)
            found += [stretch] if stretch is not None else []
        names = {c.name for c in found}
        kept = [s for s in sres.scores if s.name not in names]
        lag = lag_share(series, residuals, ref.currents if ref is not None else None)
        for s in kept:
            s.significant = s.significant and s.name not in UNMATCHED
            if s.name == "sensor" and lag is not None:
                # named by its signature (a lag beats the same filter as a lead); its share is
                # measured where the effect is isolated: the current of the matched loops
                s.share = s.raw_share = lag[0]
                s.ci = lag[1:]
                s.significant = s.significant and lag[0] >= cfg.min_share
        sres.scores = rank_scores(kept + found)
    gap_present = sres.physics_excess > cfg.gap_floor * (sres.physics_excess + sres.noise_level)
    sig = [s for s in sres.scores if s.significant] if gap_present else []
    top = [sig[0].name] if sig else []
    figures = {"physics": heldout_metrics(d, sres.predictions["physics"], cfg.seed),
               "layer": heldout_metrics(d, sres.predictions["layer"], cfg.seed)}
    if top:
        figures["top"] = heldout_metrics(d, sres.predictions[top[0]], cfg.seed)
    absorbed = (1.0 - sres.layer_excess / sres.physics_excess if sres.physics_excess > 0
                else float("nan"))
    verdict, summary = _structure_verdict(gap_present, absorbed, sres.layer_ratio, sig, figures,
                                          matched)
    summary += spread_note(sres.scores) if gap_present else ""
    cands = [CandidateScore(s.name, s.title, f"depends on {s.condition}", {}, s.share, s.ci,
                            s.significant, s.raw_share, {}, {}, "signature")
             for s in sres.scores]
    structure = {
        "grid_rows": len(d), "grid_held_out_rows": int(d.test.sum()),
        "configurations": sorted({s.config for s in series}),
        "catheters": sorted({s.catheter for s in series if s.catheter}),
        "physics_excess": sres.physics_excess, "layer_excess": sres.layer_excess,
        "layer_absorbs": absorbed, "layer_ratio": sres.layer_ratio,
        "signatures": [vars(s) for s in sres.scores], "figures": figures,
        "protocol": matched}
    return GapResult(
        verdict=verdict, summary=summary, split="", base_params={}, fitted_params={},
        noise_std={n: float(np.sqrt(v)) for n, v in zip(CHANNELS, noise_var, strict=True)},
        gap_ratio=(sres.layer_ratio, float("nan"), float("nan")), before={},
        after_top=figures.get("top"), after_combined=figures.get("top"), top=top,
        combined=top, combined_share=(sig[0].share, *sig[0].ci) if sig else None,
        candidates=cands, where_shares={}, where_bins={}, ljung_box_base={},
        timing_s={"signatures": time.perf_counter() - t0}, rows={"grid": len(d)},
        structure=structure)


def rank_scores(scores: Sequence[SignatureScore]) -> list[SignatureScore]:
    """By share, a significant compliance after every other score: a coupling or a current lag
    also moves its reversals' figure, and they are tested on matched contrasts that a
    compliance leaves alone (docs/gap.md). Significant matched loop tests take their places
    among themselves by the size of their contrast: a share says how well the effect model
    reproduces a contrast, not how large it is, and a catheter whose base has a small effect
    of its own (the coilpipe plant's rate dependence, 0.3 deg) reproduces it as well as the
    large one added (session 11)."""
    ordered = sorted(scores, key=lambda s: (s.name == "compliance" and s.significant, -s.share))
    loops = [i for i, s in enumerate(ordered)
             if s.significant and s.name in LOOP_TESTS and np.isfinite(s.size_deg)]
    by_size = sorted((ordered[i] for i in loops), key=lambda s: -s.size_deg)
    for i, s in zip(loops, by_size, strict=True):
        ordered[i] = s
    return ordered


def spread_note(scores: Sequence[SignatureScore]) -> str:
    """The verdict's sentence for effects inside the model's units' spread: their contrast
    beyond the model's mean unit would be named, but the model's own units scatter as far, so
    an effect cannot be told from unit scatter (docs/gap.md "Session 17"). Empty when none."""
    inside = [s for s in scores if np.isfinite(s.within_spread_deg)]
    return "".join(
        f" {s.title[0].upper()}{s.title[1:]} present beyond this catheter model's mean unit "
        f"({s.within_spread_deg:.2f} deg of contrast), but not clearly beyond the spread of "
        f"its units ({s.spread_deg:.2f} deg): an effect cannot be told from unit scatter; "
        f"compare with "
        f"more units of the model, or test the effect by changing its condition on the rig."
        for s in inside)


def _residuals(series: Sequence[GapSeries], split: Split, ev: Evaluator,
               base_fit: Prediction) -> list[NDArray[np.float64]]:
    """Data minus the physics simulator on every row of the protocol recordings (others: 0)."""
    out = []
    for s, blk, ho in zip(series, split.block, split.held_out, strict=True):
        if s.segment is None:
            out.append(np.zeros((len(s), 4)))
            continue
        rows = np.arange(len(s))
        view = View(s, rows, ~ho, ho, blk, smooth_velocity(s.t_s, s.knob_deg))
        pred = ev.predict([view], [], coefs=base_fit.coefs).values[0]
        out.append(view.measured - pred)
    return out


def _matched_score(score: Any) -> bool:
    """Whether a score came from the matched protocol (its share is of a matched contrast)."""
    return score.name in DECIDES.values() or score.name in ("sensor", "compliance")


def _structure_verdict(gap_present: bool, absorbed: float, layer_ratio: float,
                       sig: list[Any], figures: dict[str, dict[str, float]],
                       matched: bool = False) -> tuple[str, str]:
    phys, lay = figures["physics"], figures["layer"]

    def tip(m: dict[str, float]) -> str:
        return " / ".join(f"{m[f'tip{k}_rmse_deg']:.3g}" for k in (1, 2)
                          if np.isfinite(m[f"tip{k}_rmse_deg"]))

    base = (f"the physics simulator leaves {tip(phys)} deg held-out tip RMSE; a hysteresis "
            f"layer fitted on training data takes it to {tip(lay)} deg ({absorbed:.0%} of the "
            f"excess over noise is base mismatch; what is left is {layer_ratio:.2f}x noise)")
    if not gap_present:
        return "none significant", (f"The simulator matches the held-out data to within the "
                                    f"noise: {base}.")
    if sig and matched and _matched_score(sig[0]):
        s = sig[0]
        return f"identified: {s.name}", (
            f"Base physics: {base}. On top of it, {s.title} ({s.condition}): its effect model, "
            f"fitted on one configuration, removes {s.share:.0%} of the matched contrast of "
            f"another (range {s.ci[0]:.0%}..{s.ci[1]:.0%}); with its per-row signature the "
            f"tip RMSE is {tip(figures['top'])} deg.")
    if sig:
        s = sig[0]
        return f"identified: {s.name}", (
            f"Base physics: {base}. On top of it, {s.title} (signature: {s.condition}) removes "
            f"{s.share:.0%} (90 % CI {s.ci[0]:.0%}..{s.ci[1]:.0%}) of the remaining excess "
            f"beyond its surrogate null; with it the tip RMSE is {tip(figures['top'])} deg.")
    return "base physics differ", (
        f"Base physics: {base}. No effect's signature beats its surrogate null: the gap is in "
        f"the base physics (dead zone, friction law, loop shape), not a missing effect.")
