"""The gap report: Markdown for a controls engineer, JSON with the same figures, PNG plots."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from tsmd.gap.model import Prediction, View
from tsmd.gap.result import GapResult


def _f(x: float | None, digits: int = 3) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "-"
    return f"{x:.{digits}g}"


def _pct(x: float) -> str:
    return "-" if math.isnan(x) else f"{100 * x:.0f} %"


METRICS: tuple[tuple[str, str], ...] = (
    ("tip1_rmse_deg", "tip 1 RMSE (deg)"), ("tip1_ptpe_deg", "tip 1 PTPE (deg)"),
    ("tip2_rmse_deg", "tip 2 RMSE (deg)"), ("tip2_ptpe_deg", "tip 2 PTPE (deg)"),
    ("cur1_rmse_A", "current 1 RMSE (A)"), ("cur2_rmse_A", "current 2 RMSE (A)"))


def markdown(result: GapResult, title: str, plots: dict[str, str]) -> str:
    """The five-minute report."""
    r = result
    lines = [f"# Sim-to-real gap: {title}", "",
             f"**Verdict: {r.verdict}.** {r.summary}", ""]
    lines += ["## How far (held-out data)", "",
              "| figure | base simulator | + top effect | + top effects together |",
              "| --- | ---: | ---: | ---: |"]
    top_name = r.top[0] if r.top else "none"
    comb_name = " + ".join(r.combined) if r.combined else "none"
    for key, label in METRICS:
        after = r.after_top or {}
        comb = r.after_combined or {}
        lines.append(f"| {label} | {_f(r.before[key])} | {_f(after.get(key))} | "
                     f"{_f(comb.get(key))} |")
    share = ("-" if r.combined_share is None else
             f"{_pct(r.combined_share[0])} (90 % CI {_pct(r.combined_share[1])}.."
             f"{_pct(r.combined_share[2])})")
    lines += ["", f"Top effect: **{top_name}**; together: **{comb_name}**, removing {share} of "
              f"the excess gap. Held-out residual / noise before: {r.gap_ratio[0]:.2f} "
              f"(90 % CI {r.gap_ratio[1]:.2f}..{r.gap_ratio[2]:.2f}; 1 = noise only).", ""]
    if "timeseries" in plots:
        lines += [f"![held-out time series]({plots['timeseries']})", ""]
    if r.structure is not None:
        lines += structure_lines(r)
        if "candidates" in plots:
            lines += [f"![signature ranking]({plots['candidates']})", ""]
        return "\n".join(lines + where_lines(r, plots) + fit_lines(r))
    lines += ["## Which effect (candidates fitted on training data, scored on held-out)", "",
              "| rank | effect | share of excess gap | 90 % CI | significant | fitted | "
              "Ljung-Box Q tip1/cur1 |", "| ---: | --- | ---: | --- | --- | --- | --- |"]
    for i, c in enumerate(r.candidates, 1):
        params = ", ".join(f"{k}={v:.3g}" for k, v in c.params.items()) or "linear terms"
        lines.append(
            f"| {i} | {c.title} | {_pct(c.share)} | {_pct(c.ci[0])}..{_pct(c.ci[1])} | "
            f"{'yes' if c.significant else 'no'} | {params} | "
            f"{_f(c.ljung_box_q['tip1'])} / {_f(c.ljung_box_q['cur1'])} |")
    lines += ["", f"Base simulator Ljung-Box Q tip1/cur1: {_f(r.ljung_box_base['tip1'])} / "
              f"{_f(r.ljung_box_base['cur1'])} (20 lags; smaller = whiter residual).", ""]
    if "candidates" in plots:
        lines += [f"![candidate ranking]({plots['candidates']})", ""]
    return "\n".join(lines + where_lines(r, plots) + fit_lines(r))


def structure_lines(r: GapResult) -> list[str]:
    """Signature method: base mismatch, then the effect identified on top of it."""
    st = r.structure or {}
    fig = st.get("figures", {})
    cols = [("physics", "physics simulator"), ("layer", "+ structural layer"),
            ("top", f"+ {r.top[0]}" if r.top else "+ effect (none)")]
    lines = ["## Base physics and the effect on top (held-out rows of the signature grid)", "",
             "| figure | " + " | ".join(c[1] for c in cols) + " |",
             "| --- |" + " ---: |" * len(cols)]
    for key, label in METRICS:
        cells = []
        for name, _ in cols:
            m = fig.get(name)
            if m is None:
                cells.append("-")
                continue
            cell = _f(m.get(key))
            lo, hi = key.replace("_rmse_", "_rmse_lo_"), key.replace("_rmse_", "_rmse_hi_")
            if "_rmse_" in key and lo in m:
                cell += f" ({_f(m[lo])}..{_f(m[hi])})"
            cells.append(cell)
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    lines += ["", f"RMSE with its 90 % block-bootstrap interval. The structural layer (a "
              f"generalized Prandtl-Ishlinskii hysteresis of each knob around the simulator, "
              f"fitted on training rows) absorbs {_pct(st.get('layer_absorbs', math.nan))} of "
              f"the simulator's held-out excess over noise: that part of the gap is the base "
              f"physics. What it leaves is {st.get('layer_ratio', math.nan):.2f}x the noise.",
              "", "## Which effect (signatures against surrogate nulls)", "",
              "| rank | effect | depends on | share beyond null | 90 % CI | significant | "
              "true condition | surrogates |",
              "| ---: | --- | --- | ---: | --- | --- | ---: | ---: |"]
    for i, sgn in enumerate(st.get("signatures", []), 1):
        lines.append(f"| {i} | {sgn['title']} | {sgn['condition']} | {_pct(sgn['share'])} | "
                     f"{_pct(sgn['ci'][0])}..{_pct(sgn['ci'][1])} | "
                     f"{'yes' if sgn['significant'] else 'no'} | {_pct(sgn['raw_share'])} | "
                     f"{_pct(sgn['null_share'])} |")
    lines += ["", "Shares are of the excess the structural layer leaves on held-out blocks; "
              "'beyond null' subtracts what the same regressors built from a surrogate condition "
              "(shifted in time, a slow wave for time, configurations re-drawn, a lead for a lag) "
              "remove. Significant: the true condition's gain lies above the surrogates' spread "
              "(z above the one-sided 5 % / number of signatures point), the one-sided block-"
              "bootstrap bound at that level is above zero, and the share is at least 5 %.", ""]
    if st.get("protocol"):
        lines += ["The recordings carry the matched-condition protocol: rate, coupling, drift / "
                  "creep and curvature are scored by the difference between matched segments "
                  "instead (z from the analysis of variance against repeats of the same "
                  "condition; share: what an effect model fitted on one configuration's "
                  "contrast removes of another's); sensor dynamics keeps its signature, its "
                  "share measured on the matched loops' current. Compliance is named only "
                  "with the model's data sheet (--compliance-sheet): the lost motion per "
                  "ampere at the reversals, 60 against 40 deg, at least 1.25x the sheet's at "
                  "its lower bound, and only when no other effect is significant; without a "
                  "sheet it is shown but not named (docs/gap.md).", ""]
    return lines


def where_lines(r: GapResult, plots: dict[str, str]) -> list[str]:
    """Where the simulator's held-out gap lies."""
    lines = ["## Where the gap is (base simulator, held-out residuals)", "",
              "Share of the residual sum of squares that one constant offset removes, and that "
              "each factor's bin means remove beyond it:", "",
              "| factor | tip | current |", "| --- | ---: | ---: |"]
    for factor in r.where_shares["tip"]:  # "constant offset" first, then the factors
        lines.append(f"| {factor.replace('_', ' ')} | {_pct(r.where_shares['tip'][factor])} | "
                     f"{_pct(r.where_shares['current'][factor])} |")
    for group in ("tip", "current"):
        shares = {k: v for k, v in r.where_shares[group].items() if k != "constant offset"}
        factor = max(shares, key=lambda k: shares[k])
        lines += ["", f"{group.capitalize()} residual by {factor.replace('_', ' ')} "
                  f"(largest factor):", "",
                  "| bin | share of rows | share of gap | RMS | mean |",
                  "| --- | ---: | ---: | ---: | ---: |"]
        for b in r.where_bins[group]:
            if b.factor == factor:
                lines.append(f"| {b.bin} | {_pct(b.share_rows)} | {_pct(b.share_gap)} | "
                             f"{_f(b.rms)} | {_f(b.mean)} |")
    if "where" in plots:
        lines += ["", f"![where the gap is]({plots['where']})"]
    return lines


def fit_lines(r: GapResult) -> list[str]:
    """Split, fitted parameters, noise floor and cost."""
    return ["", "## Base fit", "",
              f"- Split: {r.split}; {r.rows['held_out']} of {r.rows['total']} rows held out.",
              "- Fitted plant parameters: " + (", ".join(
                  f"{k}={v:.4g}" for k, v in r.fitted_params.items()) or "none"),
              "- Noise floor (from the measurements): " + ", ".join(
                  f"{k} {v:.3g}" for k, v in r.noise_std.items()),
              f"- Wall time {r.timing_s['total']:.1f} s; {r.rows['simulated']} plant steps, "
              f"{r.rows['model_evaluations']} model evaluations.", "",
              "How to read: see docs/gap.md. Shares are of the *excess* gap (held-out residual "
              "above the noise floor, in noise units, summed over tip and current). An effect is "
              "significant when it removes at least 5 % and its one-sided bootstrap lower bound "
              "(over held-out time blocks) at 5 % / number of candidates tried is above zero "
              "(Bonferroni); the table shows the 90 % interval.", ""]


def plots(result: GapResult, out_dir: Path, prefix: str = "gap") -> dict[str, str]:
    """Write the PNGs; return name -> file name (relative to ``out_dir``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir.mkdir(parents=True, exist_ok=True)
    files: dict[str, str] = {}
    views: list[View] = result.plot_data.get("views", [])
    base: Prediction | None = result.plot_data.get("base")
    top: Prediction | None = result.plot_data.get("top")
    with_test = [j for j, v in enumerate(views) if v.test.any()]
    if with_test and base is not None:
        # the widest held-out motion, among the views that have held-out rows at all
        i = max(with_test, key=lambda j: float(np.ptp(views[j].knob_deg[views[j].test])))
        v = views[i]
        knob = int(np.argmax(np.ptp(v.knob_deg, axis=0)))
        t = v.t_s - v.series.t_s[0]
        meas = v.measured
        fig, axes = plt.subplots(3, 1, figsize=(7, 7.5))
        for ax, c, unit in ((axes[0], knob, "tip (deg)"), (axes[1], 2 + knob, "current (A)")):
            ax.plot(t[~v.test], meas[~v.test, c], ".", color="0.75", ms=1.5, label="train")
            ax.plot(t[v.test], meas[v.test, c], "k.", ms=1.5, label="held out")
            ax.plot(t, base.values[i][:, c], lw=1, label="base sim")
            if top is not None:
                ax.plot(t, top.values[i][:, c], lw=1, label=f"+ {result.top[0]}")
            ax.set_ylabel(f"knob {knob + 1} {unit}")
        axes[0].legend(fontsize=7, ncol=4)
        axes[1].set_xlabel(f"time in {v.series.name} (s)")
        axes[2].plot(v.knob_deg[:, knob], meas[:, knob], "k.", ms=1.5, label="measured")
        axes[2].plot(v.knob_deg[:, knob], base.values[i][:, knob], lw=1, label="base sim")
        if top is not None:
            axes[2].plot(v.knob_deg[:, knob], top.values[i][:, knob], lw=1,
                         label=f"+ {result.top[0]}")
        axes[2].set_xlabel(f"knob {knob + 1} (deg)")
        axes[2].set_ylabel(f"tip {knob + 1} (deg)")
        axes[2].legend(fontsize=7)
        fig.tight_layout()
        name = f"{prefix}_timeseries.png"
        fig.savefig(out_dir / name, dpi=72)
        plt.close(fig)
        files["timeseries"] = name
    if result.candidates:
        fig, ax = plt.subplots(figsize=(6, 2.8))
        names = [c.name for c in result.candidates][::-1]
        share = np.array([c.share for c in result.candidates][::-1])
        lo = np.array([c.ci[0] for c in result.candidates][::-1])
        hi = np.array([c.ci[1] for c in result.candidates][::-1])
        colors = ["tab:green" if c.significant else "tab:gray" for c in result.candidates][::-1]
        ax.barh(names, share, color=colors,
                xerr=np.vstack([np.maximum(share - lo, 0), np.maximum(hi - share, 0)]))
        ax.axvline(0, color="k", lw=0.8)
        ax.set_xlabel("share of held-out excess gap removed (90 % CI)")
        fig.tight_layout()
        name = f"{prefix}_candidates.png"
        fig.savefig(out_dir / name, dpi=80)
        plt.close(fig)
        files["candidates"] = name
    if result.where_shares:
        fig, ax = plt.subplots(figsize=(6, 2.8))
        factors = [f for f in result.where_shares["tip"] if f != "constant offset"]
        x = np.arange(len(factors))
        ax.bar(x - 0.2, [result.where_shares["tip"][f] for f in factors], 0.4, label="tip")
        ax.bar(x + 0.2, [result.where_shares["current"][f] for f in factors], 0.4,
               label="current")
        ax.set_xticks(x, [f.replace("_", "\n") for f in factors], fontsize=7)
        ax.set_ylabel("share of gap held")
        ax.legend(fontsize=7)
        fig.tight_layout()
        name = f"{prefix}_where.png"
        fig.savefig(out_dir / name, dpi=80)
        plt.close(fig)
        files["where"] = name
    return files


def write_report(result: GapResult, out_dir: Path, title: str,
                 extra: dict[str, Any] | None = None) -> tuple[Path, Path]:
    """Write ``gap_report.json``, ``gap_report.md`` and the plots into ``out_dir``.

    The figures are written first, and a failing plot stage costs only the plots (its reason is
    kept in the report): minutes of diagnosis are never lost to a drawing problem.
    """
    out_dir.mkdir(parents=True, exist_ok=True)
    data = result.to_json()
    data["title"] = title
    if extra:
        data.update(extra)
    js = out_dir / "gap_report.json"
    md = out_dir / "gap_report.md"

    def save(files: dict[str, str], plot_error: str | None) -> None:
        data["plots"] = files
        data["plot_error"] = plot_error
        js.write_text(json.dumps(finite_json(data), indent=2, default=_jsonable,
                                 allow_nan=False), encoding="utf-8")
        text = markdown(result, title, files)
        if plot_error:
            text += f"\nPlots not drawn: {plot_error}\n"
        md.write_text(text, encoding="utf-8")

    save({}, None)
    try:
        files, error = plots(result, out_dir), None
    except Exception as exc:  # any drawing failure must not lose the figures
        files, error = {}, f"{type(exc).__name__}: {exc}"
    save(files, error)
    return md, js


def finite_json(x: Any) -> Any:
    """NaN/inf (a channel that was not measured) become null: strict JSON."""
    if isinstance(x, dict):
        return {k: finite_json(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [finite_json(v) for v in x]
    if isinstance(x, float | np.floating) and not math.isfinite(float(x)):
        return None
    return x


def _jsonable(x: Any) -> Any:
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(f"not JSON serialisable: {type(x).__name__}")
