"""Shape changes mid-run in the plant's own physics (simrig.scenario, capstan reshape)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from simrig.plant import PlantLoadError, PlantStep
from simrig.plants.capstan import make_tendon_sheath_plant
from simrig.scenario import ShapeChange, ShapeChangePlant


def tip_edge_deg(plant: object, dt_s: float = 0.004) -> float:
    """Knob 1 angle where the tip first passes 1 deg on a slow rise from 0 to 60 deg."""
    for x in np.arange(0.0, 60.0, 0.02):
        step = plant.step(dt_s, np.array([x, 0.0]))  # type: ignore[attr-defined]
        if step.tip_deg[0] > 1.0:
            return float(x)
    raise AssertionError("the tip never moved")


def test_more_slack_moves_the_engagement_by_the_slack_over_the_pulley_radius() -> None:
    straight = tip_edge_deg(make_tendon_sheath_plant())
    slack = ShapeChangePlant(make_tendon_sheath_plant(),
                             [ShapeChange(0.0, {"slack_delta_mm": ((0.5, 0.5), (0.0, 0.0))})])
    expected = math.degrees(0.5 / 6.0)  # 0.5 mm on the 6 mm pulley
    assert tip_edge_deg(slack) - straight == pytest.approx(expected, abs=0.3)


def test_a_curved_sheath_widens_the_dead_zone() -> None:
    straight = tip_edge_deg(make_tendon_sheath_plant())
    curved = ShapeChangePlant(make_tendon_sheath_plant(),
                              [ShapeChange(0.0, {"sheath_curvature_deg": 90.0})])
    assert tip_edge_deg(curved) > straight + 3.0


def test_the_change_takes_effect_at_its_time_and_once() -> None:
    plant = ShapeChangePlant(make_tendon_sheath_plant(),
                             [ShapeChange(1.0, {"sheath_curvature_deg": 45.0})])
    for _ in range(200):  # 0.8 s
        plant.step(0.004, np.zeros(2))
    assert plant.applied == [] and plant.effects.sheath_curvature_deg == 0.0
    for _ in range(100):
        step = plant.step(0.004, np.zeros(2))
    assert isinstance(step, PlantStep)
    assert len(plant.applied) == 1 and plant.applied[0][0] == pytest.approx(1.0, abs=0.005)
    assert plant.effects.sheath_curvature_deg == 45.0


def test_a_plant_without_reshape_is_refused_in_one_line() -> None:
    class Rigid:
        def reset(self) -> None: ...

        def step(self, dt_s: float, knob_deg: np.ndarray) -> PlantStep:
            return PlantStep(np.zeros(2), np.zeros(2))

    with pytest.raises(PlantLoadError, match="cannot change shape"):
        ShapeChangePlant(Rigid(), [ShapeChange(1.0, {"sheath_curvature_deg": 10.0})])
