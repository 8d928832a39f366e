"""Calibration report: Markdown plus PNG plots (matplotlib, Agg backend, no display needed).

Per knob: the filtered current of every sweep against knob angle with the detected backlash
ends, dead-zone edges and peaks; D and B over the other knob's angle with the interpolation the
compensator uses; the paper's model curve over the sweep at the other knob's 0 deg, beside the
tracked tip when the recording has one (simulator, TEE data: evaluation only).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tsmd.calibration.assemble import KNOB_LABELS, GridPoint, knob_grid
from tsmd.calibration.offline import identification_table
from tsmd.calibration.resweep import point_estimates
from tsmd.calibration.sweep_result import PARAMETERS, SHORT

if TYPE_CHECKING:
    from tsmd.calibration.run import Calibration


def grid_table(cal: Calibration) -> str:
    """D and B per knob and grid point with their 95 % uncertainty (what sweeps narrow and what
    the current cannot show of the unit, :attr:`Estimate.reported_u95_deg`), as Markdown."""
    estimates = dict(zip((id(p) for p in cal.points), point_estimates(cal.points), strict=True))
    lines = []
    for knob in (0, 1):
        grid, _ = knob_grid(cal.points, knob)
        if not grid:
            continue
        kp = cal.profile.knobs[knob]
        lines.append(f"{KNOB_LABELS[knob]}: H_pos {kp.height_pos_deg:.1f} deg, "
                     f"H_neg {kp.height_neg_deg:.1f} deg, omega {kp.omega:g}")
        head = [f"{KNOB_LABELS[1 - knob]} (deg)", *(f"{SHORT[p]} +- 95 %" for p in PARAMETERS),
                "re-sweeps", "SNR"]
        lines += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        for other in grid:
            point = next(p for p in cal.points if p.knob == knob and p.other_deg == other)
            est = estimates[id(point)]
            cells = [f"{other:+.0f}", *(f"{est[n].value:.1f} +- {est[n].reported_u95_deg:.1f}"
                                         for n in PARAMETERS),
                     str(point.result.resweeps), f"{point.result.median_snr:.0f}"]
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")
    lines += [f"- {note}" for note in cal.notes]
    return "\n".join(lines)


def write_report(cal: Calibration, directory: Path) -> Path:
    """Write ``<dir>/<catheter>.md`` and its PNGs; return the Markdown path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    directory.mkdir(parents=True, exist_ok=True)
    cid = cal.profile.catheter_id
    images: list[tuple[str, str]] = []
    for knob in (0, 1):
        mine = sorted((p for p in cal.points if p.knob == knob), key=lambda p: p.other_deg)
        if not mine:
            continue
        label = KNOB_LABELS[knob]
        name = f"{cid}-{label}-current.png"
        _plot_currents(plt, mine, directory / name)
        images.append((f"{label}: current against knob angle", name))
        name = f"{cid}-{label}-parameters.png"
        _plot_parameters(plt, cal, knob, directory / name)
        images.append((f"{label}: D and B over the other knob's angle", name))
        name = f"{cid}-{label}-model.png"
        if _plot_model(plt, cal, knob, mine, directory / name):
            images.append((f"{label}: the paper's model over the sweep at "
                           f"{KNOB_LABELS[1 - knob]} = 0", name))
    md = [f"# Calibration report: {cid}", "",
          f"- device model: {cal.profile.device_model}",
          f"- calibrated at: {cal.profile.calibrated_at} (tsmd {cal.profile.software_version})",
          f"- source: {cal.profile.source}; protocol: {cal.protocol_name or '-'}"]
    if cal.sweep_time_s:
        md.append(f"- time: {cal.sweep_time_s:.0f} s sweeping, {cal.motion_time_s:.0f} s of "
                  f"motion, {cal.wall_time_s:.1f} s wall")
    md += ["", "## Identified parameters (median over the half-cycles)", "", grid_table(cal),
           "## Every half-cycle", "", identification_table(cal.points), "",
           "## Quality", ""]
    md += [f"- {k}: {v:.2f}" for k, v in sorted(cal.quality.figures.items())]
    md += [f"- **warning**: {w}" for w in cal.quality.warnings]
    notes = sorted({n for p in cal.points for n in p.result.data.notes})
    if notes:
        md += ["", "Signal conditioning notes: " + "; ".join(notes)]
    md.append("")
    for title, name in images:
        md += [f"## {title}", "", f"![{title}]({name})", ""]
    path = directory / f"{cid}.md"
    path.write_text("\n".join(md), encoding="utf-8")
    return path


def _plot_currents(plt: object, points: list[GridPoint], path: Path) -> None:
    n = len(points)
    cols = min(4, n)
    rows = math.ceil(n / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 2.5 * rows),  # type: ignore[attr-defined]
                             squeeze=False, sharex=True)
    for ax, p in zip(axes.flat, points, strict=False):
        d = p.result.data
        for h in p.result.data_half_cycles:  # a re-sweep's index its own recording
            sl = slice(h.start, h.stop)
            color = "tab:red" if h.direction > 0 else "tab:blue"
            ax.plot(d.pos_deg[sl], d.current_filtered_A[sl] * 1e3, color=color, lw=0.8)
            for idx, marker, c in ((h.peak_index, "^", "k"), (h.backlash_end_index, "o", "m"),
                                   (h.edge_index, "s", "g")):
                if idx is not None:
                    ax.plot(d.pos_deg[idx], d.current_filtered_A[idx] * 1e3, marker, color=c,
                            ms=4)
        ax.set_title(f"other {p.other_deg:+.0f} deg", fontsize=8)
        ax.tick_params(labelsize=7)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.supxlabel("knob angle (deg)   ^ peak, o backlash end, s dead-zone edge", fontsize=8)
    fig.supylabel("current (mA, filtered)", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=70)
    plt.close(fig)  # type: ignore[attr-defined]


def _plot_parameters(plt: object, cal: Calibration, knob: int, path: Path) -> None:
    from tsmd.compensation.grid import ParameterField

    grid, values = knob_grid(cal.points, knob)
    fig, axes = plt.subplots(1, 2, figsize=(8, 3))  # type: ignore[attr-defined]
    fine = np.linspace(min(grid), max(grid), 181)
    for ax, names in zip(axes, (PARAMETERS[:2], PARAMETERS[2:]), strict=True):
        for name in names:
            v = np.array(values[name])
            ax.plot(grid, v, "o", label=SHORT[name])
            if len(grid) >= 2 and np.all(np.isfinite(v)):
                f = ParameterField(grid, v[:, None], cal.profile.interpolation)
                ax.plot(fine, [float(f.at(a)[0]) for a in fine], "-", lw=1)
        ax.set_xlabel(f"{KNOB_LABELS[1 - knob]} (deg)")
        ax.set_ylabel("knob deg")
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=70)
    plt.close(fig)  # type: ignore[attr-defined]


def _plot_model(plt: object, cal: Calibration, knob: int, points: list[GridPoint],
                path: Path) -> bool:
    from tsmd.compensation.paper import PaperParams, initial_state, model_step

    zero = min(points, key=lambda p: abs(p.other_deg))
    kp = cal.profile.knobs[knob]
    r = zero.result
    try:
        params = PaperParams(r.estimate("dead_zone_pos_deg"), r.estimate("dead_zone_neg_deg"),
                             r.estimate("backlash_pos_deg"), r.estimate("backlash_neg_deg"),
                             kp.height_pos_deg, kp.height_neg_deg, kp.omega)
    except ValueError:
        return False
    d = r.data
    start = min((h.start for h in r.data_half_cycles), default=0)
    x = d.pos_deg[start:]
    state = initial_state(float(x[0]), params, direction=-1)
    model = []
    for xi in x:
        state, _ = model_step(state, float(xi), params)
        model.append(state.y_deg)
    fig, ax = plt.subplots(figsize=(5, 4))  # type: ignore[attr-defined]
    rec = zero.recording
    col = f"tip{knob + 1}"
    if rec is not None and col in rec.columns and np.isfinite(rec[col]).any():
        tip = np.interp(d.t_s, rec["t"], rec[col])[start:]
        ax.plot(x, tip, color="0.6", lw=1, label="tracked tip (evaluation only)")
    ax.plot(x, model, color="tab:red", lw=1.2, label="paper model from current")
    ax.set_xlabel("knob angle (deg)")
    ax.set_ylabel("tip angle (deg)")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=70)
    plt.close(fig)  # type: ignore[attr-defined]
    return True
