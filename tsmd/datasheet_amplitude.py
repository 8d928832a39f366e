"""How the tip's backlash grows with the reversal's amplitude, tracked on the data sheet's unit.

Method ours makes the backlash after a reversal proportional to the load there, ``B = beta (x_r -
x0)``, and fits ``beta`` and ``x0`` on the one amplitude calibration reverses at (+-90 deg); the
release line is then moved to the product's release-path slope ratio through that backlash end
(:mod:`tsmd.calibration.release_path`). Which gain the ratio is taken against (the settle
rule's or the product rule's) sets how the backlash scales down to smaller reversals, and the
current cannot tell (session 16, helixbelt: the settle rule's made unit 2's phi2 backlash at a
60 deg reversal 9.2 deg against the tip's 6.7). The tracker can: each knob is swept +-60 and
+-90 deg (0.04 Hz, other knob at 0) and the tip's backlash read as the scoring truth reads it
(:func:`tsmd.tip_truth.tip_reading`); its growth per degree of amplitude is
``reference_tip_backlash_gain``, against which the ratio's gain is chosen.

Read at the 1 deg threshold, a tip that starts back gradually after a reversal (friction
distributed along the tendon: presliding, rounded corners) shows a backlash that grows more
slowly than the knob travel to the release line the model draws (ratestate's sheet unit: 0.133
per degree at the threshold, 0.173 to the line, whose every release path is one line). The
growth read at the corners of the paper's lines (``by="lines"``) is
``reference_tip_line_backlash_gain`` (session 17); where the sheet has it, the ratio's gain is
chosen against it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from simrig.analysis import SweepAnalysisError
from simrig.plant import Plant
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.datasheet import CONDITIONING_CYCLES, SWEEP_AMPLITUDE_DEG, SWEEP_HZ, settle
from tsmd.errors import TsmdError
from tsmd.replay import run_trajectory
from tsmd.tip_truth import tip_reading

SMALL_AMPLITUDE_DEG = 60.0
"""The second reversal amplitude (the accuracy scenarios' +-60 deg)."""
AMPLITUDE_CYCLES = 2.0
"""Analysed cycles per amplitude, after the conditioning cycle."""


def amplitude_sweep(knob: int, amplitude_deg: float, period_s: float
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A +-``amplitude_deg``, 0.04 Hz sweep of ``knob`` (other knob at 0), conditioning first."""
    t = np.arange(0.0, (CONDITIONING_CYCLES + AMPLITUDE_CYCLES) / SWEEP_HZ, period_s)
    q = np.zeros((t.size, 2))
    q[:, knob] = amplitude_deg * np.sin(2 * math.pi * SWEEP_HZ * t)
    return t, q


def tip_backlash_deg(plant_factory: Callable[[], Plant], knob: int, amplitude_deg: float,
                     seed: int, config: TsmdConfig, by: str = "threshold"
                     ) -> tuple[float, float]:
    """The tip's backlash (positive, negative side) after reversals at +-``amplitude_deg``,
    read ``by`` one of :data:`tsmd.tip_truth.TRUTHS`."""
    period_s = config.loop.period_s
    t, q, skip = settle(*amplitude_sweep(knob, amplitude_deg, period_s), period_s)
    rec = run_trajectory(t, q, config=config, profile=None, method="none", seed=seed,
                         plant=plant_factory())
    a = skip + round(CONDITIONING_CYCLES / SWEEP_HZ / period_s)
    k = knob + 1
    try:
        b = tip_reading(rec["t"][a:], rec[f"cmd{k}"][a:], rec[f"pos{k}"][a:], rec[f"tip{k}"][a:],
                        by)
    except SweepAnalysisError as exc:
        raise TsmdError(f"tip backlash gain: knob {k} at +-{amplitude_deg:g} deg: {exc}") from None
    return float(b.backlash_pos_deg), float(b.backlash_neg_deg)


def measure_tip_backlash_gains(plant_factory: Callable[[], Plant], seed: int = 2000,
                               config: TsmdConfig | None = None, by: str = "threshold"
                               ) -> tuple[float | None, float | None]:
    """Each knob's tip backlash growth per degree of reversal amplitude (mean of both sides,
    from +-60 to +-90 deg), read ``by`` the threshold or the lines; None where a side's
    backlash could not be read."""
    cfg = config if config is not None else default_sim_config()
    gains = [backlash_growth(
        tip_backlash_deg(plant_factory, knob, SMALL_AMPLITUDE_DEG, seed, cfg, by),
        tip_backlash_deg(plant_factory, knob, SWEEP_AMPLITUDE_DEG, seed, cfg, by))
        for knob in (0, 1)]
    return gains[0], gains[1]


def backlash_growth(small_deg: tuple[float, float], large_deg: tuple[float, float],
                    small_amplitude_deg: float = SMALL_AMPLITUDE_DEG,
                    large_amplitude_deg: float = SWEEP_AMPLITUDE_DEG) -> float | None:
    """Backlash growth per degree of amplitude, mean of both sides ((pos, neg) backlashes at
    the two amplitudes); None where a side is not finite."""
    g = 0.5 * ((large_deg[0] - small_deg[0]) + (large_deg[1] - small_deg[1]))
    g /= large_amplitude_deg - small_amplitude_deg
    return g if math.isfinite(g) else None
