"""The paper's tracking scenarios, the conditioned start and the tracking errors.

What is run (:func:`scenarios`, :func:`conditioned`) and how it is scored
(:func:`tracking_errors`); :mod:`tsmd.bench.accuracy` runs them through the full stack,
:mod:`tsmd.bench.family_accuracy` per catheter unit, and the data sheet's release-ratio gain
choice (:mod:`tsmd.datasheet_ratio_gain`) on the sheet's unit: outside :mod:`tsmd.bench`
(moved from ``tsmd/bench/accuracy_scenarios.py`` in session 22), because the daemon's modules
do not import the benchmarks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tsmd.config import default_sim_config
from tsmd.datasheet import settle

PERIOD_S = default_sim_config().loop.period_s
"""The bench runs on the packaged simulated rig: trajectories at that loop's own tick."""

@dataclass(frozen=True)
class Scenario:
    """One trajectory of the protocol; ``knobs`` are the knobs whose tracking is scored."""

    group: str
    name: str
    t_s: NDArray[np.float64]
    q_deg: NDArray[np.float64]
    knobs: tuple[int, ...]


CONDITIONING_HZ = 0.08


def conditioned(t: NDArray[np.float64], q: NDArray[np.float64], condition: bool
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64], int]:
    """``settle``, optionally after one unscored +-90 deg cycle of both knobs at 0.08 Hz.

    A fresh simulated plant is tension-free, a state a catheter that has been calibrated (the
    paper's experiments follow the calibration on the same catheter) is never in. With
    ``condition`` every run starts from the state one full cycle leaves.
    """
    tt, qq, skip = settle(t, q, PERIOD_S)
    if not condition:
        return tt, qq, skip
    tc = np.arange(0.0, 1.0 / CONDITIONING_HZ, PERIOD_S)
    cond = np.repeat((90.0 * np.sin(2 * math.pi * CONDITIONING_HZ * tc))[:, None], 2, axis=1)
    full: NDArray[np.float64] = np.vstack([cond, qq]).astype(float)
    t_full: NDArray[np.float64] = np.arange(len(full), dtype=float) * PERIOD_S
    return t_full, full, skip + len(cond)


def scenarios(quick: bool = False) -> list[Scenario]:
    """The paper's scenarios (section "Scenarios"): 1-DOF with the other knob fixed, 2-DOF."""
    f1 = 0.04
    cycles = 1 if quick else 2
    t = np.arange(0.0, cycles / f1, PERIOD_S)
    fixed = (0.0, 60.0) if quick else (-60.0, -30.0, 0.0, 30.0, 60.0)
    out: list[Scenario] = []
    periodic = 60.0 * np.sin(2 * math.pi * f1 * t)
    for knob in (0, 1):
        for other in fixed:
            q = np.zeros((t.size, 2))
            q[:, knob] = periodic
            q[:, 1 - knob] = other
            out.append(Scenario("1-DOF periodic", f"phi{knob + 1}, other at {other:+.0f}",
                                t, q, (knob,)))
    t_np = np.arange(0.0, (0.5 if quick else 1.0) / 0.02, PERIOD_S)

    def nonperiodic(tt: NDArray[np.float64], scale: float) -> NDArray[np.float64]:
        return (30.0 * np.sin(2 * math.pi * 0.02 * scale * tt)
                + 30.0 * np.sin(2 * math.pi * 0.02 * math.sqrt(3.0) * scale * tt))

    for knob in (0, 1):
        q = np.zeros((t_np.size, 2))
        q[:, knob] = nonperiodic(t_np, 1.0)
        out.append(Scenario("1-DOF non-periodic", f"phi{knob + 1}, other at +0", t_np, q,
                            (knob,)))
    q2 = np.column_stack([periodic, 60.0 * np.sin(2 * math.pi * 2 * f1 * t)])
    out.append(Scenario("2-DOF periodic", "phi1 0.04 Hz, phi2 0.08 Hz", t, q2, (0, 1)))
    q2n = np.column_stack([nonperiodic(t_np, 1.0), nonperiodic(t_np, 2.0)])
    out.append(Scenario("2-DOF non-periodic", "phi1 0.02+0.035 Hz, phi2 twice", t_np, q2n,
                        (0, 1)))
    return out


def tracking_errors(tip_deg: NDArray[np.float64], q_deg: NDArray[np.float64]
                    ) -> tuple[float, float]:
    """(PTPE, RMSE) of tip against desired: peak-to-peak of the error and its RMS."""
    e = np.asarray(tip_deg, float) - np.asarray(q_deg, float)
    e = e[np.isfinite(e)]
    if e.size == 0:
        return math.nan, math.nan
    return float(e.max() - e.min()), float(np.sqrt(np.mean(e * e)))
