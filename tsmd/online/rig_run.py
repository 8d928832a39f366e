"""Online re-estimation on the simulated rig: the mixed motion and one lockstep run with our
compensator and an online worker.

One home for what the online bench (:mod:`tsmd.bench.online`) and the data sheet's slope
reading (:mod:`tsmd.datasheet_bend_slope`, the sheet's unit driven through its bends) both run;
the daemon's data sheet must not import the benchmarks.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.daemon import make_compensator
from tsmd.loop import ROW_COLUMNS
from tsmd.online.worker import OnlineWorker
from tsmd.replay import LockstepRunner

Array = NDArray[np.float64]
PERIOD_S = 0.004
DRAIN_EVERY = 25


def mixed_motion(duration_s: float, seed: int) -> tuple[Array, Array]:
    """Both knobs, each a slow large sine plus a faster smaller one (phases from ``seed``)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration_s, PERIOD_S)
    ph = rng.uniform(0.0, 2 * math.pi, 4)
    q1 = 45.0 * np.sin(2 * math.pi * 0.06 * t + ph[0]) + 12.0 * np.sin(2 * math.pi * 0.17 * t
                                                                        + ph[1])
    q2 = 42.0 * np.sin(2 * math.pi * 0.05 * t + ph[2]) + 12.0 * np.sin(2 * math.pi * 0.14 * t
                                                                        + ph[3])
    ramp = np.clip(t / 2.0, 0.0, 1.0)  # start from rest
    return t, np.column_stack([q1 * ramp, q2 * ramp])


def run(profile: Any, plant: Any, t: Array, q: Array, online: bool, seed: int,
        device: Any = None, bend: Any = None) -> tuple[Any, Any]:
    """One lockstep run with our compensator; returns (recording, worker or None). The
    worker takes each knob's handle slip and torque ripple period from ``device``'s data
    sheet and the product's bend relation ``bend`` (None: none)."""
    with LockstepRunner(None, profile, "ours", seed, plant) as runner:
        comp = make_compensator(profile, "ours", runner.config)
        runner.loop.execute("set_compensator", compensator=comp, label="ours")
        worker = None
        if online:
            slip = None if device is None else (device.knobs[0].handle_slip_deg,
                                                 device.knobs[1].handle_slip_deg)
            ripple = None if device is None else (device.knobs[0].torque_ripple_period_deg,
                                                   device.knobs[1].torque_ripple_period_deg)
            worker = OnlineWorker(comp, runner.loop.period_s, ROW_COLUMNS,
                                  handle_slip_deg=slip, ripple_period_deg=ripple,
                                  drain_every=DRAIN_EVERY,
                                  fault_reason=lambda: runner.loop.fault_reason, bend=bend)
            runner.loop.observer = worker.observe
        rec = runner.run(t, q, compensate=True)
    return rec, worker


__all__ = ["DRAIN_EVERY", "PERIOD_S", "mixed_motion", "run"]
