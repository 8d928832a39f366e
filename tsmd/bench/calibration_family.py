"""The calibration on a family of simulated catheters: acceptance, accuracy against the tip,
wall time split between the stack and the plant, and refusal of injected faults.

One *run* is one catheter (a plant built with a unit seed) and one noise seed (current sensor
and tracker). Each run plays the chosen protocols on fresh rigs; the truth at each of the
paper's 7 grid points per knob is read off the tracked tip of the paper protocol's sweep there
(:func:`tsmd.tip_truth.tip_truth`), or, when the paper protocol is not run, of the
same sweeps played on the plant alone (:func:`truth_sweeps`), so every profile is judged on the
same 56 values per catheter (the fast one interpolated over the other knob's angle as the
profile is, pchip).
"""

from __future__ import annotations

import dataclasses
import math
import resource
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from tsmd.calibration.protocol import fast_protocol, paper_protocol
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.profile import DeviceModel
from tsmd.tip_truth import tip_truth
from tsmd.tracked_calibration import (
    LIMIT_DEG,
    TARGET_DEG,
    ProtocolRun,
    play_protocol,
    score,
    truth_sweeps,
)


def unit_config(base: TsmdConfig, plant: str, params: dict[str, Any], unit_key: str,
                unit: int) -> TsmdConfig:
    """The sim config of one catheter of the family."""
    sim = dataclasses.replace(base.sim, plant=plant, params={**params, unit_key: unit})
    return base.replace(sim=sim)


@dataclass
class CatheterRun:
    """Both protocols on one catheter with one noise seed."""

    plant: str
    unit: int
    noise_seed: int
    runs: dict[str, ProtocolRun]
    peak_rss_MiB: float


def run_catheter(plant: str, params: dict[str, Any], unit_key: str, unit: int, noise_seed: int,
                 device: DeviceModel, protocols: Sequence[str] = ("paper", "fast"),
                 config: TsmdConfig | None = None) -> CatheterRun:
    """The paper protocol (it gives the truth) and the others on one catheter."""

    cfg = unit_config(config or default_sim_config(), plant, params, unit_key, unit)
    makers = {"paper": paper_protocol, "fast": fast_protocol}
    runs = {name: play_protocol(cfg, device, makers[name](), noise_seed) for name in protocols}
    paper = runs.get("paper")
    full = paper is not None and len(paper.points) == len(paper_protocol().sweeps)
    truth_points = paper.points if full and paper else truth_sweeps(cfg)
    truth = {(p.knob, p.other_deg): tip_truth(p) for p in truth_points}
    truth_lines = {(p.knob, p.other_deg): tip_truth(p, "lines") for p in truth_points}
    for run in runs.values():
        score(run, truth, truth_lines)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return CatheterRun(plant, unit, noise_seed,
                       {k: v for k, v in runs.items() if k in protocols}, rss)


def family_table(results: Sequence[CatheterRun], protocol: str) -> str:
    """One row per catheter and noise seed, then the family's figures and the worst unit."""
    head = ["unit", "noise seed", "accepted", "re-sweeps", "sweeping (s)",
            f"within {TARGET_DEG:g} deg", "max error (deg)", "wall (s)", "plant share"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    rows = [(c, c.runs[protocol]) for c in results if protocol in c.runs]
    for c, r in rows:
        share = r.plant_s / r.wall_s if r.wall_s > 0 else math.nan
        lines.append(
            f"| {c.unit} | {c.noise_seed} | {'yes' if r.accepted else 'NO'} | "
            f"{len(r.resweeps)} | {r.sweep_time_s:.0f} | {r.within}/{len(r.errors)} | "
            f"{r.max_error:.2f} | {r.wall_s:.1f} | {share:.0%} |")
    if not rows:
        return "(no runs)"
    accepted = sum(r.accepted for _, r in rows)
    good = sum(r.within >= 0.95 * len(r.errors) for _, r in rows)
    under3 = sum(r.max_error <= LIMIT_DEG for _, r in rows)
    values = np.concatenate([np.asarray(r.errors, float) for _, r in rows])
    worst_c, worst = min(rows, key=lambda cr: (cr[1].within, -cr[1].max_error))
    lines += [
        "",
        f"- accepted: {accepted} of {len(rows)} runs ({accepted / len(rows):.0%})",
        f"- runs with >= 95 % of the values within {TARGET_DEG:g} deg: {good} of {len(rows)}; "
        f"with none beyond {LIMIT_DEG:g} deg: {under3} of {len(rows)}",
        f"- all values: {int(np.sum(values <= TARGET_DEG))} of {values.size} within "
        f"{TARGET_DEG:g} deg, mean |error| {np.nanmean(values):.2f} deg, max "
        f"{np.nanmax(values):.2f} deg",
        f"- worst: unit {worst_c.unit} noise seed {worst_c.noise_seed}: {worst.within}/"
        f"{len(worst.errors)} within {TARGET_DEG:g} deg, max {worst.max_error:.2f} deg"
        + ("" if worst.accepted else f", refused: {worst.reason[:200]}"),
    ]
    lines += line_truth_summary(rows)
    lines += coverage_summary(rows)
    refused = [(c, r) for c, r in rows if not r.accepted]
    lines += [f"- refused: unit {c.unit} seed {c.noise_seed}: {r.reason[:300]}"
              for c, r in refused]
    return "\n".join(lines)


def line_truth_summary(rows: Sequence[tuple[CatheterRun, ProtocolRun]]) -> list[str]:
    """The family's figures again against the line truth (where the runs carry it)."""
    scored = [(c, r) for c, r in rows if r.errors_lines]
    if not scored:
        return []
    values = np.concatenate([np.asarray(r.errors_lines, float) for _, r in scored])
    good = sum(int(np.sum(np.asarray(r.errors_lines) <= TARGET_DEG)) >= 0.95 * len(r.errors_lines)
               for _, r in scored)
    return [f"- against the line truth (corners of the paper's lines on the tip): "
            f"{int(np.sum(values <= TARGET_DEG))} of {values.size} within {TARGET_DEG:g} deg, "
            f"runs >= 95 %: {good} of {len(scored)}, max {np.nanmax(values):.2f} deg"]


def coverage_summary(rows: Sequence[tuple[CatheterRun, ProtocolRun]]) -> list[str]:
    """How often the reported 95 % half-widths cover the tip's truth, per kind, over the runs
    and on the worst-covered run (an honest half-width: about 95 %; far above it is too wide)."""
    kinds = sorted({kind for _, r in rows for kind in r.coverage})
    if not kinds:
        return []
    parts = []
    for kind in kinds:
        got = [(c, r.coverage[kind]) for c, r in rows if r.coverage.get(kind, (0, 0))[1]]
        if not got:
            continue
        covered, n = (sum(x[i] for _, x in got) for i in (0, 1))
        worst_c, (wc, wn) = min(got, key=lambda cx: cx[1][0] / cx[1][1])
        parts.append(f"{kind} {covered}/{n} ({covered / n:.0%}; worst unit {worst_c.unit} "
                     f"seed {worst_c.noise_seed} {wc}/{wn})")
    return [f"- reported 95 % half-width covers the tip's threshold truth (grid points "
            f"measured): {'; '.join(parts)}"] if parts else []


def run_catheter_summary(plant: str, params: dict[str, Any], unit_key: str, unit: int,
                         noise_seed: int, device: DeviceModel,
                         protocols: Sequence[str] = ("paper", "fast")) -> CatheterRun:
    """:func:`run_catheter` without the recordings and signals (small to send between
    processes): the verdicts, the estimates and the errors."""
    result = run_catheter(plant, params, unit_key, unit, noise_seed, device, protocols)
    for run in result.runs.values():
        run.points = [dataclasses.replace(p, recording=None) for p in run.points]
    return result
