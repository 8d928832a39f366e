"""The stick-slip plant: stable, deterministic, symmetric, resettable; its mechanisms act."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from simrig.analysis import measure_dead_zone_backlash
from simrig.plant import PlantLoadError, load_plant
from simrig.plants.stickslip import StickSlipPlant, make_stickslip_plant

SPEC = "simrig.plants.stickslip:make_stickslip_plant"
SYMMETRIC = {"free_length_neg_m": 0.10}
"""The nominal antagonist is routed longer; with equal routing a knob is mirror-symmetric."""


def _sweep(plant: StickSlipPlant, dt_s: float, amplitude_deg: float = 90.0,
           period_s: float = 8.0, other_deg: float = 0.0, cycles: float = 1.25
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Knob 1 on a sine from 0 (fast: a quasi-static plant does not care about the rate)."""
    t = np.arange(dt_s, cycles * period_s + dt_s / 2, dt_s)
    q = amplitude_deg * np.sin(2 * np.pi * t / period_s)
    tip = np.empty_like(q)
    torque = np.empty_like(q)
    for i, qi in enumerate(q):
        step = plant.step(dt_s, np.array([qi, other_deg]))
        tip[i], torque[i] = step.tip_deg[0], step.knob_torque_Nm[0]
    return q, tip, torque


def test_a_sweep_stays_finite_and_close_at_plant_steps_from_100_us_to_4_ms() -> None:
    tips = []
    for dt_s in (1e-4, 4e-3):
        plant = make_stickslip_plant(knobs=[{"creep_fast_share": 0.0, "creep_slow_share": 0.0},
                                            {}])
        _, tip, torque = _sweep(plant, dt_s, period_s=2.0, cycles=0.75)
        assert np.all(np.isfinite(tip)) and np.all(np.isfinite(torque))
        tips.append(tip[-1])
    assert abs(tips[0] - tips[1]) < 1.0


def test_the_same_inputs_give_the_same_outputs() -> None:
    a = _sweep(make_stickslip_plant(), 0.004, period_s=4.0)
    b = _sweep(make_stickslip_plant(), 0.004, period_s=4.0)
    assert np.array_equal(a[1], b[1]) and np.array_equal(a[2], b[2])


def test_a_knob_with_equal_routing_bends_the_tip_mirror_symmetrically() -> None:
    up = make_stickslip_plant(knobs=[SYMMETRIC, {}])
    down = make_stickslip_plant(knobs=[SYMMETRIC, {}])
    for q in np.linspace(0.0, 80.0, 120):
        a = up.step(0.004, np.array([q, 0.0]))
        b = down.step(0.004, np.array([-q, 0.0]))
    assert a.tip_deg[0] == pytest.approx(-b.tip_deg[0], abs=1e-6)
    assert a.knob_torque_Nm[0] == pytest.approx(-b.knob_torque_Nm[0], abs=1e-9)


def test_the_nominal_antagonist_routing_makes_the_knob_asymmetric() -> None:
    up, down = make_stickslip_plant(), make_stickslip_plant()
    for q in np.linspace(0.0, 80.0, 120):
        a = up.step(0.004, np.array([q, 0.0]))
        b = down.step(0.004, np.array([-q, 0.0]))
    assert abs(a.tip_deg[0] + b.tip_deg[0]) > 0.05


def test_reset_returns_the_tip_to_straight_and_unloaded() -> None:
    plant = make_stickslip_plant()
    _sweep(plant, 0.004, period_s=4.0, cycles=0.3)
    plant.reset()
    step = plant.step(0.004, np.array([0.0, 0.0]))
    assert np.all(step.tip_deg == 0.0) and np.all(step.knob_torque_Nm == 0.0)


def test_the_nominal_unit_has_a_dead_zone_and_backlash_of_the_papers_order() -> None:
    q, tip, _ = _sweep(make_stickslip_plant(), 0.004, period_s=8.0, cycles=2.25)
    m = measure_dead_zone_backlash(q[250:], tip[250:])
    assert 12.0 < m.dead_zone_pos_deg < 30.0 and 10.0 < m.backlash_pos_deg < 30.0
    assert 60.0 < tip.max() < 95.0


@pytest.mark.parametrize(("dt_s", "knob"), [(-0.001, [0.0, 0.0]), (0.004, [float("nan"), 0.0]),
                                            (0.004, [1.0]), (0.004, "ab")])
def test_bad_step_input_is_refused(dt_s: float, knob: Any) -> None:
    with pytest.raises(ValueError):
        make_stickslip_plant().step(dt_s, knob)


@pytest.mark.parametrize(("params", "message"), [
    ({"knobs": [{"pulley_radius_mm": 0.0}, {}]}, r"knobs\[0\].pulley_radius_mm must be > 0"),
    ({"knobs": [{}, {"bogus": 1.0}]}, r"knobs\[1\]: unknown parameter 'bogus'"),
    ({"knobs": [{}]}, "knobs must be a list of 2 mappings"),
    ({"knobs": [{"stiction_ratio": 0.5}, {}]}, r"knobs\[0\].stiction_ratio must be >= 1"),
    ({"sheath_curvature_deg": -5.0}, "sheath_curvature_deg must be finite and >= 0"),
    ({"foo": 1}, "unexpected keyword argument 'foo'"),
])
def test_bad_parameters_are_refused_by_name(params: dict[str, Any], message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        load_plant(SPEC, params)


def test_the_polymer_tendon_relaxes_the_drive_torque_during_a_hold() -> None:
    def relaxed_share(shares: dict[str, float]) -> float:
        plant = make_stickslip_plant(knobs=[shares, {}])
        _sweep(plant, 0.004, period_s=8.0, cycles=0.25)
        first = plant.step(0.004, np.array([90.0, 0.0])).knob_torque_Nm[0]
        for _ in range(2500):  # 10 s hold at the top
            last = plant.step(0.004, np.array([90.0, 0.0])).knob_torque_Nm[0]
        return float((first - last) / first)

    assert relaxed_share({}) > 0.05
    assert abs(relaxed_share({"creep_fast_share": 0.0, "creep_slow_share": 0.0})) < 1e-3


def test_the_knob_brake_makes_the_drive_torque_jump_at_a_reversal_in_the_dead_zone() -> None:
    plant = make_stickslip_plant()
    torques = [plant.step(0.004, np.array([q, 0.0])).knob_torque_Nm[0]
               for q in [*np.linspace(0.0, 8.0, 40), *np.linspace(8.0, 0.0, 40)]]
    assert torques[39] > 0.01 and torques[-1] < -0.01


def test_bending_the_other_plane_widens_this_knobs_backlash() -> None:
    def backlash(other_deg: float) -> float:
        plant = make_stickslip_plant()
        for q in np.linspace(0.0, other_deg, 200):
            plant.step(0.004, np.array([0.0, q]))
        q, tip, _ = _sweep(plant, 0.004, period_s=8.0, other_deg=other_deg, cycles=2.25)
        return float(measure_dead_zone_backlash(q[250:], tip[250:]).backlash_pos_deg)

    assert backlash(80.0) > backlash(0.0) + 0.5


def test_a_longer_tendon_widens_the_dead_zone() -> None:
    def dead_zone(delta_mm: float) -> float:
        plant = make_stickslip_plant()
        plant.reshape(slack_delta_mm=((delta_mm, delta_mm), (0.0, 0.0)))
        q, tip, _ = _sweep(plant, 0.004, period_s=8.0, cycles=2.25)
        return float(measure_dead_zone_backlash(q[250:], tip[250:]).dead_zone_pos_deg)

    assert dead_zone(0.5) > dead_zone(0.0) + 2.0
