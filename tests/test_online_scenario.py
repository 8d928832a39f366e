"""Shape changes mid-run in the plant's own physics (simrig.scenario, capstan and lumped
reshape)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.plants import knob1_sweep

from simrig.plant import PlantLoadError, PlantStep
from simrig.plants.capstan import make_tendon_sheath_plant
from simrig.plants.lumped import make_lumped_plant
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


def test_lumped_more_slack_moves_the_engagement_by_the_slack_over_the_pulley_radius() -> None:
    straight = tip_edge_deg(make_lumped_plant())
    slack = ShapeChangePlant(make_lumped_plant(),
                             [ShapeChange(0.0, {"slack_delta_mm": ((0.5, 0.5), (0.0, 0.0))})])
    expected = math.degrees(0.5 / 6.0)  # 0.5 mm on the 6 mm pulley
    assert tip_edge_deg(slack) - straight == pytest.approx(expected, abs=0.3)


def test_lumped_slack_change_is_the_plant_built_with_that_slack() -> None:
    built = make_lumped_plant(knobs=[{"slack_pos_mm": 2.6 + 0.4, "slack_neg_mm": 2.7 - 0.2}, {}])
    reshaped = make_lumped_plant()
    reshaped.reshape(slack_delta_mm=((0.4, -0.2), (0.0, 0.0)))
    _, tip_a, tau_a = knob1_sweep(built, cycles=1.0)
    _, tip_b, tau_b = knob1_sweep(reshaped, cycles=1.0)
    np.testing.assert_allclose(tip_b, tip_a, atol=1e-9)
    np.testing.assert_allclose(tau_b, tau_a, atol=1e-12)


def test_lumped_curved_sheath_widens_the_dead_zone_by_the_lumen_clearance() -> None:
    straight = tip_edge_deg(make_lumped_plant())
    curved = make_lumped_plant()
    curved.reshape(sheath_curvature_deg=90.0)
    # 0.3 mm of path per radian of bend, on the 6 mm pulley
    expected = math.degrees(0.3e-3 * math.radians(90.0) / 6e-3)
    assert tip_edge_deg(curved) - straight == pytest.approx(expected, abs=0.6)


def test_lumped_curved_sheath_raises_the_loaded_torque_and_the_hysteresis() -> None:
    q, tip_s, tau_s = knob1_sweep(make_lumped_plant(), cycles=1.0)
    curved = make_lumped_plant()
    curved.reshape(sheath_curvature_deg=90.0)
    _, tip_c, tau_c = knob1_sweep(curved, cycles=1.0)
    rising = (np.gradient(q) > 0) & (q > 60.0)
    # more wrap on the distal lumps: more friction, so the pulling torque rises
    assert np.mean(tau_c[rising]) > 1.05 * np.mean(tau_s[rising])
    # ... and less of the knob reaches the tip while pulling
    assert np.max(tip_c) < np.max(tip_s) - 1.0


def test_lumped_reshape_mid_run_keeps_the_tendon_state() -> None:
    plant = make_lumped_plant()
    for x in np.linspace(0.0, 60.0, 600):
        before = plant.step(0.004, np.array([x, 0.0]))
    plant.reshape(sheath_curvature_deg=0.0)  # the same shape again: nothing may jump
    after = plant.step(0.004, np.array([60.0, 0.0]))
    assert after.tip_deg[0] == pytest.approx(before.tip_deg[0], abs=0.05)
    assert after.knob_torque_Nm[0] == pytest.approx(before.knob_torque_Nm[0], rel=0.02)


def test_lumped_reshape_refuses_a_negative_slack_in_one_line() -> None:
    with pytest.raises(PlantLoadError, match="makes a slack negative"):
        make_lumped_plant().reshape(slack_delta_mm=((-5.0, 0.0), (0.0, 0.0)))
