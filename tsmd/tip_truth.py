"""The truth a calibration is scored against: D and B read off the simulated tip of its sweeps.

Shared by the calibration benchmark and its family runs; the tip is ground truth for evaluation
only, never an input of the calibration.
"""

from __future__ import annotations

import numpy as np

from simrig.analysis import (
    DeadZoneBacklash,
    SweepAnalysisError,
    measure_by_lines,
    measure_dead_zone_backlash,
)
from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.identify import split_half_cycles
from tsmd.calibration.signal import lowpass

TIP_THRESHOLD_DEG = 1.0
"""How far the tip must move off its plateau for an edge or a backlash end (deg)."""

TRUTHS = {"threshold": measure_dead_zone_backlash, "lines": measure_by_lines}
"""The two readings of the tip: where it has moved 1 deg (a dead-zone edge: 1 deg off the line
its plateau follows, so a creeping plateau is not read mid-plateau; session 21), and the
corners of the paper's lines (fitted over whole branches; the plateau with its own slope). They
differ by up to ~3 deg on a curved branch, so a score names its truth."""


def tip_truth(point: GridPoint, by: str = "threshold", tip_noise_deg: float = 0.0,
              noise_seed: int = 0) -> dict[str, float]:
    """D and B measured on the tracked tip of the sweep (the plant package's analysis), read
    ``by`` one of :data:`TRUTHS`; with ``tip_noise_deg``, on the tip plus that much white
    noise (seeded): how a tracker's noise moves the reading."""
    rec = point.recording
    if rec is None:
        return {}
    k = point.knob + 1
    start = float(rec.metadata["calibration_sweep_start_s"]) - 1.0  # include the way down to -A
    m = rec["t"] >= start
    t, pos, tip = rec["t"][m], rec[f"pos{k}"][m], rec[f"tip{k}"][m]
    if not np.isfinite(tip).all():
        return {}
    if tip_noise_deg > 0.0:
        tip = tip + np.random.default_rng(noise_seed).normal(0.0, tip_noise_deg, tip.size)
    try:
        truth = tip_reading(t, rec[f"cmd{k}"][m], pos, tip, by)
    except SweepAnalysisError:
        return {}
    return dict(truth._asdict())


def tip_reading(t_s: np.ndarray, cmd_deg: np.ndarray, pos_deg: np.ndarray,
                tip_deg: np.ndarray, by: str = "threshold") -> DeadZoneBacklash:
    """D and B of one tracked sweep as the truth reads them: the tip low-passed at the
    current's cutoff (zero phase; on the raw tracker 0.1 deg of noise fires the 1 deg threshold
    1.5-2.5 deg early on a slowly starting tip), the knob made monotonic between reversals.
    Raises :class:`simrig.analysis.SweepAnalysisError` where the sweep shows neither."""
    tip_f, _ = lowpass(np.asarray(tip_deg, dtype=float), 1.0 / float(np.median(np.diff(t_s))))
    knob = monotone_knob(np.asarray(cmd_deg, dtype=float), np.asarray(pos_deg, dtype=float))
    return TRUTHS[by](knob, tip_f, threshold_deg=TIP_THRESHOLD_DEG)


def monotone_knob(cmd_deg: np.ndarray, pos_deg: np.ndarray) -> np.ndarray:
    """The actual knob angle made monotonic between the command's reversals.

    At a speed change the drive's position wobbles back by ~0.02 deg; the plant analysis cuts
    passes at every direction change, so without this a wobble becomes a "reversal" and the
    tip's backlash comes out as the 1 deg threshold's knob travel.
    """
    out = np.asarray(pos_deg, dtype=float).copy()
    for direction, a, b, _ in split_half_cycles(np.asarray(cmd_deg, dtype=float), 10.0):
        out[a:b] = direction * np.maximum.accumulate(direction * out[a:b])
    return out
