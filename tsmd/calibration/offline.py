"""Logged sweeps for ``tsmd calibrate --from-recording``: tsmd recordings or TEE acquisitions."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.protocol import GRID_DEG
from tsmd.calibration.resweep import point_estimates, uncertainty_table
from tsmd.calibration.sweep_result import PARAMETERS, SHORT
from tsmd.recording import Recording, RecordingError, read_recording
from tsmd.tee import DEFAULT_STEPS_PER_KNOB_DEG, load_tee_acquisition


def is_tee_acquisition(path: str | os.PathLike[str]) -> bool:
    """True for a CSV in the TEE source's layout (its header names 'Motor position')."""
    try:
        with open(path, encoding="utf-8-sig") as f:
            header = f.readline()
    except (OSError, UnicodeDecodeError):
        return False
    return "Motor position" in header and "Current" in header


def read_sweep_file(path: str | os.PathLike[str],
                    steps_per_knob_deg: float | None = None) -> Recording:
    """A recording CSV, or a TEE acquisition converted (knob from the file name)."""
    if is_tee_acquisition(path):
        return load_tee_acquisition(
            path, steps_per_knob_deg=steps_per_knob_deg or DEFAULT_STEPS_PER_KNOB_DEG)
    if steps_per_knob_deg is not None:
        raise RecordingError(f"{path}: --steps-per-knob-deg applies to TEE acquisitions only")
    return read_recording(path)


def identification_table(points: Sequence[GridPoint]) -> str:
    """What each sweep gave (all half-cycle values), as a Markdown table."""
    head = ["sweep", "knob", "other (deg)", *(SHORT[p] for p in PARAMETERS), "SNR"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for p in points:
        cells = [Path(p.name).name if os.sep in p.name else p.name, f"phi{p.knob + 1}",
                 f"{p.other_deg:+.0f}"]
        for name in PARAMETERS:
            values = p.result.values.get(name, ())
            cells.append(", ".join(f"{v:.1f}" for v in values) if values else "-")
        snr = p.result.snr
        cells.append(f"{snr:.0f}" if math.isfinite(snr) else "-")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def data_report(points: Sequence[GridPoint], failures: Sequence[tuple[str, str]],
                refusal: str | None) -> str:
    """What logged sweeps give (estimates with their 95 % uncertainty) and what they lack for a
    profile, against the paper's protocol: for a refused calibration from recordings."""
    lines = ["## What the data give (median of the half-cycles +- 95 % uncertainty)", ""]
    lines.append(uncertainty_table(points) if points else "(nothing: no file could be used)")
    lines += ["", "## What they lack for a profile", ""]
    for source, reason in failures:
        lines.append(f"- {Path(source).name}: nothing could be estimated: {reason}")
    for knob, label in ((0, "phi1"), (1, "phi2")):
        mine = [p for p in points if p.knob == knob]
        angles = sorted(p.other_deg for p in mine)
        if len(angles) < len(GRID_DEG):
            lines.append(
                f"- {label}: sweeps at the other knob's {', '.join(f'{a:+.0f}' for a in angles)}"
                f" deg ({len(angles)}); a profile needs >= 2 angles including 0, the paper's "
                f"protocol sweeps {len(GRID_DEG)} ({', '.join(f'{a:+.0f}' for a in GRID_DEG)})"
                if angles else f"- {label}: no sweep")
    for p, est in zip(points, point_estimates(points), strict=True):
        d = p.result.data
        amplitude = 0.5 * float(np.ptp(d.cmd_deg))
        passes = len(p.result.half_cycles)
        takes = p.result.resweeps + 1
        lines.append(
            f"- {p.name}: {passes} passes over +-{amplitude:.0f} deg in {takes} acquisition(s) "
            f"of {d.t_s[-1] - d.t_s[0]:.0f} s (the paper: 4 passes over +-90 deg at 0.04 Hz, "
            f"50 s, at each of 7 grid points); median SNR "
            f"{p.result.median_snr:.1f} (4 needed for an edge)")
        for name, e in est.items():
            if e.n == 0:
                why = "; ".join(sorted({q.split(": ", 1)[-1] for q in p.result.problems}))
                lines.append(f"  - no {SHORT[name]}: {why or 'no half-cycle gave it'}")
            elif e.n == 1:
                lines.append(f"  - {SHORT[name]} from one half-cycle only: no scatter of its own")
    if refusal:
        lines += ["", "## Refused because", "", refusal]
    return "\n".join(lines)
