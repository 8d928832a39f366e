"""The TEE probe's signatures, measured the same way on real acquisitions and on a plant.

Part of `tsmd bench realism`: the release/loaded slope ratio of a sweep, the shape of the
current's and the tip's fall after a reversal, and each TEE acquisition replayed on a plant
through the same triangle. The same rule runs on real and simulated data, so a difference is the
plant's, not the measurement's.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.signal import medfilt

from simrig.analysis import SweepAnalysisError, loaded_slope, releasing_slope
from simrig.plant import as_plant_step, load_plant
from tsmd.errors import TsmdError
from tsmd.tee import DEFAULT_SAMPLE_PERIOD_S, knob_from_filename, load_tee_acquisition
from tsmd.tracking_scenarios import PERIOD_S

FloatArray = NDArray[np.float64]


def release_load_ratio(knob_deg: FloatArray, tip_deg: FloatArray) -> float:
    """Releasing over loaded tip/knob slope of a +-90 deg sweep, the worse side (furthest from 1).

    Loaded: moving away from zero at 40-85 deg; released: moving back at 10-60 deg, past the
    backlash. The sweep is centred on its own knob and tip midpoints, so a recording that does
    not start at the middle (the TEE acquisitions) is measured the same way.
    """
    q = np.asarray(knob_deg, dtype=float)
    y = np.asarray(tip_deg, dtype=float)
    half = 0.5 * float(np.ptp(q))
    if not half > 0.0:
        return math.nan
    scale = 90.0 / half
    qc = (q - 0.5 * (float(q.max()) + float(q.min()))) * scale
    yc = y - 0.5 * (float(y.max()) + float(y.min()))
    try:
        load = loaded_slope(qc, yc, 40.0, 85.0)
        release = releasing_slope(qc, yc, 10.0, 60.0)
    except SweepAnalysisError:
        return math.nan
    ratios = [r / lo for r, lo in zip(release, load, strict=True) if lo > 0.0]
    if not ratios:
        return math.nan
    return float(max(ratios, key=lambda v: abs(math.log(v)) if v > 0.0 else math.inf))


def reversal_shape(knob_deg: FloatArray, tip_deg: FloatArray, current: FloatArray
                   ) -> tuple[float, float]:
    """After the top reversal of a triangle: knob travel (% of the knob range) until the
    current (median-filtered, spikes out) has fallen halfway to its released level, and until
    the tip has come back by 3 % of its range. Same rule on real and simulated data."""
    c = medfilt(np.asarray(current, dtype=float), 9)
    span = float(np.ptp(knob_deg))
    i_rev = int(np.argmax(knob_deg))
    i_low = i_rev + int(np.argmin(knob_deg[i_rev:]))
    q = knob_deg[i_rev:i_low]
    travel = (knob_deg[i_rev] - q) / span
    mid = (travel > 0.3) & (travel < 0.45)
    released = float(np.median(c[i_rev:i_low][mid]))
    top = float(np.median(c[max(i_rev - 3, 0):i_rev + 1]))
    fell = np.flatnonzero(c[i_rev:i_low] < top - 0.5 * (top - released))
    moved = np.flatnonzero(tip_deg[i_rev:i_low] < tip_deg[i_rev] - 0.03 * np.ptp(tip_deg))
    return (100.0 * float(travel[fell[0]]) if fell.size else math.nan,
            100.0 * float(travel[moved[0]]) if moved.size else math.nan)


def tee_comparison(tee_dir: Path, spec: str, plot_path: Path | None) -> list[str]:
    """Each TEE acquisition against the plant driven through the same triangle, scaled to
    +-90 deg (the probe's knob range is unknown: 16 steps per degree gives about +-37)."""
    files = sorted(tee_dir.glob("motor*_*.csv"))
    if not files:
        raise TsmdError(f"no TEE acquisitions (motor*_*.csv) in {tee_dir}")
    lines = ["| acquisition | current halfway down (% of range) real / plant | tip moves back "
             "(% of range) real / plant | release/load slope real / plant |", "|---|---|---|---|"]
    panels = []
    for f in files:
        knob = knob_from_filename(f)
        rec = load_tee_acquisition(f)
        q, tip, cur = rec[f"pos{knob}"], rec[f"tip{knob}"], rec[f"cur{knob}"]
        scale = 90.0 / float(np.max(np.abs(q)))
        n_sub = round(DEFAULT_SAMPLE_PERIOD_S / PERIOD_S)
        fine = np.interp(np.arange((q.size - 1) * n_sub + 1) / n_sub, np.arange(q.size), q)
        plant = load_plant(spec)
        cmd = np.zeros(2)
        sim = np.empty((fine.size, 2))
        for i, x in enumerate(fine * scale):
            cmd[knob - 1] = x
            step = as_plant_step(plant.step(PERIOD_S, cmd))
            sim[i] = step.tip_deg[knob - 1], step.knob_torque_Nm[knob - 1]
        real_shape = reversal_shape(q, tip, cur)
        sim_shape = reversal_shape(fine, sim[:, 0], sim[:, 1])
        ratios = release_load_ratio(q, tip), release_load_ratio(fine, sim[:, 0])
        lines.append(f"| {f.stem} | {real_shape[0]:.1f} / {sim_shape[0]:.1f} | "
                     f"{real_shape[1]:.1f} / {sim_shape[1]:.1f} | "
                     f"{ratios[0]:.2f} / {ratios[1]:.2f} |")
        panels.append((f.stem, q, tip, cur, fine, sim))
    if plot_path is not None:
        _plot_tee(panels, plot_path, spec)
    return lines


def _plot_tee(panels: Sequence[tuple[str, FloatArray, FloatArray, FloatArray, FloatArray,
                                     FloatArray]], path: Path, spec: str) -> None:
    import matplotlib  # plotting only on request

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    chosen = [p for p in panels if p[0].endswith("First_acquisition")] or list(panels[:2])
    fig, axes = plt.subplots(2, len(chosen), figsize=(5.0 * len(chosen), 6.4), squeeze=False)
    for col, (name, q, tip, cur, fine, sim) in enumerate(chosen):
        for row, (real_y, sim_y, label) in enumerate(
                ((tip, sim[:, 0], "tip"), (cur, sim[:, 1], "current / knob torque"))):
            ax = axes[row, col]
            ax.plot(q / np.max(np.abs(q)), real_y / np.max(np.abs(real_y)), lw=0.7,
                    color="tab:grey", label="TEE probe (real)")
            ax.plot(fine / np.max(np.abs(fine)), sim_y / np.max(np.abs(sim_y)), lw=1.1,
                    color="tab:red", label="plant")
            ax.set_xlabel("knob / its largest excursion")
            ax.set_ylabel(f"{label} / its peak")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="upper left")
        axes[0, col].set_title(name, fontsize=9)
    fig.suptitle(f"TEE acquisitions against {spec} on the same triangle (normalised)",
                 fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=72)
    plt.close(fig)
