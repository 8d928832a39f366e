"""Shared test stand-ins for the drivers tests."""

from __future__ import annotations

import numpy as np

from simrig.plant import PlantStep


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
