"""Shared test stand-ins for the drivers tests."""

from __future__ import annotations

from typing import Any

import numpy as np

from simrig.plant import Plant, PlantStep, as_plant_step


class SpringPlant:
    """Stand-in catheter: a linear torsion spring per knob, tip = 1.3 x knob."""

    def __init__(self, stiffness_Nm_deg: float = 0.002) -> None:
        self.stiffness = stiffness_Nm_deg

    def reset(self) -> None:
        pass

    def step(self, dt_s: float, knob_deg: np.ndarray) -> PlantStep:
        return PlantStep(tip_deg=1.3 * knob_deg, knob_torque_Nm=self.stiffness * knob_deg)


class PairPlant(SpringPlant):
    """The same spring written as a user would without tsmd's types: ``step`` returns a pair."""

    def step(self, dt_s: float,  # type: ignore[override]
             knob_deg: np.ndarray) -> tuple[list[float], list[float]]:
        return ([1.3 * float(x) for x in knob_deg],
                [self.stiffness * float(x) for x in knob_deg])


def knob1_sweep(plant: Any, freq_hz: float = 0.04, cycles: float = 1.5, other_deg: float = 0.0,
                dt_s: float = 0.008) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Knob 1 swept +-90 deg (sine from 0), knob 2 held; (knob, tip, torque) of knob 1.

    The built-in plants are quasi-static: the coarse default tick keeps plant tests fast.
    """
    t = np.arange(0.0, cycles / freq_hz, dt_s)
    q = 90.0 * np.sin(2.0 * np.pi * freq_hz * t)
    tip = np.empty_like(q)
    tau = np.empty_like(q)
    cmd = np.array([0.0, other_deg])
    for i, qi in enumerate(q):
        cmd[0] = qi
        step = as_plant_step(plant.step(dt_s, cmd))
        tip[i] = step.tip_deg[0]
        tau[i] = step.knob_torque_Nm[0]
    return q, tip, tau


def ramp_knobs(plant: Plant, start: tuple[float, float], end: tuple[float, float], dt_s: float,
               rate_deg_s: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """Move both knobs linearly from ``start`` to ``end`` (the farther one at ``rate_deg_s``);
    the last step's tip and knob torque."""
    a, b = np.asarray(start, float), np.asarray(end, float)
    n = max(2, int(np.max(np.abs(b - a)) / (rate_deg_s * dt_s)))
    step = None
    for s in np.linspace(0.0, 1.0, n):
        step = as_plant_step(plant.step(dt_s, a + s * (b - a)))
    assert step is not None
    return np.asarray(step.tip_deg), np.asarray(step.knob_torque_Nm)
