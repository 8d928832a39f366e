"""Logged sweeps for ``tsmd calibrate --from-recording``: tsmd recordings or TEE acquisitions."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.identify import PARAMETERS
from tsmd.recording import Recording, RecordingError, read_recording
from tsmd.tee import DEFAULT_STEPS_PER_KNOB_DEG, load_tee_acquisition

SHORT = {"dead_zone_pos_deg": "D_pos", "dead_zone_neg_deg": "D_neg",
         "backlash_pos_deg": "B_pos", "backlash_neg_deg": "B_neg"}


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
