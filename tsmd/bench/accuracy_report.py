"""The accuracy bench's output: the table of none / paper / ours per scenario group (mean and
spread over noise seeds, improvements against the paper's published rates) and the paper-style
time and input-output plots."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # the runs are made by tsmd.bench.accuracy, which imports this module
    from tsmd.bench.accuracy import RunResult

METHODS = ("none", "paper", "ours")

PAPER_IMPROVEMENT_PCT: dict[str, tuple[float, float]] = {
    "1-DOF periodic": (63.8, 73.2),
    "1-DOF non-periodic": (48.1, 63.8),
    "2-DOF periodic": (40.5, 58.0),
    "2-DOF non-periodic": (43.7, 55.3),
}
"""The paper's improvement rates (PTPE %, RMSE %), Tables 1d_all and 2d_all."""

GOAL_RMSE_PCT = {"1-DOF": 85.0, "2-DOF": 75.0}


def _mean_std(values: Sequence[float]) -> tuple[float, float]:
    a = np.asarray(values, float)
    return float(a.mean()), float(a.std(ddof=1)) if a.size > 1 else 0.0


def summarise(results: Sequence[RunResult], key: Callable[[RunResult], str]
              ) -> dict[str, dict[str, dict[str, tuple[float, float]]]]:
    """{row: {method: {"ptpe"|"rmse": (mean, std over seeds)}}}; within a seed, the scenarios of
    a row are averaged first (as the paper pools conditions)."""
    table: dict[str, dict[str, dict[str, tuple[float, float]]]] = {}
    order = list(PAPER_IMPROVEMENT_PCT)
    rows = sorted({key(r) for r in results},
                  key=lambda k: (order.index(k) if k in order else len(order), k))
    for row in rows:
        table[row] = {}
        for method in METHODS:
            chosen = [r for r in results if key(r) == row and r.method == method]
            seeds = sorted({r.seed for r in chosen})
            per_seed_p = [float(np.mean([r.ptpe_deg for r in chosen if r.seed == s]))
                          for s in seeds]
            per_seed_r = [float(np.mean([r.rmse_deg for r in chosen if r.seed == s]))
                          for s in seeds]
            table[row][method] = {"ptpe": _mean_std(per_seed_p), "rmse": _mean_std(per_seed_r)}
    return table


def _pct(none: float, other: float) -> float:
    return 100.0 * (none - other) / none if none > 0 else math.nan


def format_table(table: dict[str, dict[str, dict[str, tuple[float, float]]]],
                 with_paper: bool) -> list[str]:
    head = ("| scenario | none PTPE | none RMSE | paper PTPE | paper RMSE | ours PTPE | ours RMSE "
            "| paper impr. PTPE/RMSE | ours impr. PTPE/RMSE |")
    if with_paper:
        head += " published impr. PTPE/RMSE | goal RMSE |"
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for row, m in table.items():
        cells = [row]
        for method in METHODS:
            for metric in ("ptpe", "rmse"):
                mean, std = m[method][metric]
                cells.append(f"{mean:.2f} ± {std:.2f}")
        for method in ("paper", "ours"):
            cells.append(f"{_pct(m['none']['ptpe'][0], m[method]['ptpe'][0]):.1f} % / "
                         f"{_pct(m['none']['rmse'][0], m[method]['rmse'][0]):.1f} %")
        if with_paper:
            pub = PAPER_IMPROVEMENT_PCT.get(row)
            cells.append(f"{pub[0]:.1f} % / {pub[1]:.1f} %" if pub else "")
            goal = GOAL_RMSE_PCT.get(row.split(" ")[0])
            cells.append(f">= {goal:.0f} %" if goal else "")
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def plot_runs(runs: Sequence[RunResult], path: Path, title: str) -> None:
    """Time and input-output curves (paper's Figs. result_1dof / result_2dof)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    knobs = runs[0].scenario.knobs
    fig, axes = plt.subplots(2, len(knobs), figsize=(5.2 * len(knobs), 6.4), squeeze=False)
    colours = {"none": "tab:blue", "paper": "tab:orange", "ours": "tab:red"}
    for col, k in enumerate(knobs):
        ax_t, ax_io = axes[0, col], axes[1, col]
        ref = runs[0]
        ax_t.plot(ref.t_s, ref.q_deg[:, k], "k:", lw=1.2, label="desired")
        lim = float(np.max(np.abs(ref.q_deg[:, k]))) * 1.15
        ax_io.plot([-lim, lim], [-lim, lim], "k:", lw=1.0)
        for r in runs:
            ax_t.plot(r.t_s, r.tip_deg[:, k], color=colours[r.method], lw=0.9, label=r.method)
            ax_io.plot(r.q_deg[:, k], r.tip_deg[:, k], color=colours[r.method], lw=0.8)
        ax_t.set_xlabel("time (s)")
        ax_t.set_ylabel(f"tip phi{k + 1} (deg)")
        ax_io.set_xlabel(f"desired phi{k + 1} (deg)")
        ax_io.set_ylabel(f"tip phi{k + 1} (deg)")
        for ax in (ax_t, ax_io):
            ax.grid(alpha=0.3)
        ax_t.legend(fontsize=7, loc="upper right")
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=72)
    plt.close(fig)
