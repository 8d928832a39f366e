"""The jawcrimp plant (blind, then held out, in session 20): laws, registration, refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.plant_drive import STEP_S, drive_knob, ramp_deg

from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import Plant, PlantLoadError, load_plant
from simrig.plants.jawcrimp import NOMINAL_KNOBS, JawCrimpPlant, make_jawcrimp_plant
from simrig.plants.jawcrimp.laws import (
    crimp_creep_rate_mm_s,
    friction_node,
    heart_pulse,
    jaw_torque_Nmm,
    shaft_shortening_mm,
)
from simrig.plants.jawcrimp.params import node_friction

SPEC = "simrig.plants.jawcrimp:make_jawcrimp_plant"


def test_the_jaw_coupling_is_loose_in_its_play_then_stiffens_with_squeeze() -> None:
    inside, k_inside = jaw_torque_Nmm(0.01, 0.02, 5.0, 0.02, 30.0)
    assert inside == pytest.approx(0.05) and k_inside == pytest.approx(5.0)
    _, k_little = jaw_torque_Nmm(0.025, 0.02, 5.0, 0.02, 30.0)
    squeezed, k_much = jaw_torque_Nmm(0.06, 0.02, 5.0, 0.02, 30.0)
    assert k_much > 3.0 * k_little
    assert jaw_torque_Nmm(-0.06, 0.02, 5.0, 0.02, 30.0)[0] == pytest.approx(-squeezed)


def test_the_friction_node_holds_within_its_capacity_then_slides_at_it() -> None:
    held = friction_node(1.0, 0.0, 0.5, 10.0, 10.0, 0.3, 0.0)
    assert held[2] == 0.5 and held[0] == pytest.approx(5.0) and held[1] == pytest.approx(5.0)
    t1, t2, x, *_ = friction_node(3.0, 0.0, 0.5, 10.0, 10.0, 0.3, 0.2)
    assert x > 0.5
    assert t1 - t2 == pytest.approx(0.2 + 0.3 * (t1 + t2))


def test_a_released_rope_slides_back_with_the_tip_pulling_it() -> None:
    t1, t2, x, *_ = friction_node(0.0, 0.0, 1.0, 10.0, 10.0, 0.3, 0.2)
    assert x < 1.0
    assert t2 - t1 == pytest.approx(0.2 + 0.3 * (t1 + t2))


def test_the_shaft_closes_its_gaps_first_then_compresses_solid() -> None:
    soft = shaft_shortening_mm(1.0, 0.5, 3.0, 150.0)[1]
    stiff = shaft_shortening_mm(30.0, 0.5, 3.0, 150.0)[1]
    assert soft > 5.0 * stiff
    assert shaft_shortening_mm(-4.0, 0.5, 3.0, 150.0)[0] == 0.0


def test_the_crimp_creeps_faster_under_more_load_and_hardens_with_its_slip() -> None:
    light = crimp_creep_rate_mm_s(5.0, 0.0, 1e-3, 10.0, 3.0, 0.05)
    heavy = crimp_creep_rate_mm_s(20.0, 0.0, 1e-3, 10.0, 3.0, 0.05)
    hardened = crimp_creep_rate_mm_s(20.0, 0.1, 1e-3, 10.0, 3.0, 0.05)
    assert heavy == pytest.approx(64.0 * light)
    assert hardened < 0.2 * heavy
    assert crimp_creep_rate_mm_s(0.0, 0.0, 1e-3, 10.0, 3.0, 0.05) == 0.0


def test_the_node_friction_stays_below_one_on_a_long_wrap() -> None:
    knob = NOMINAL_KNOBS[0]
    assert node_friction(knob, 0.0) < node_friction(knob, 120.0) < node_friction(knob, 2000.0)
    assert node_friction(knob, 2000.0) < 1.0


def test_the_heart_pulse_averages_to_zero_over_a_beat() -> None:
    t = np.linspace(0.0, 1.0, 2001)[:-1]
    assert abs(np.mean([heart_pulse(x, 1.0, 30.0) for x in t])) < 1e-9


def test_the_plant_follows_the_protocol_and_loads_by_name() -> None:
    plant = load_plant(SPEC)
    assert isinstance(plant, Plant) and isinstance(plant, JawCrimpPlant)


def _sweep(plant: JawCrimpPlant) -> tuple[np.ndarray, np.ndarray]:
    path = np.concatenate([ramp_deg(0.0, 80.0), ramp_deg(80.0, -80.0), ramp_deg(-80.0, 0.0)])
    return drive_knob(plant, 0, path)


def test_same_inputs_give_the_same_outputs() -> None:
    a = _sweep(family_member("jawcrimp", 3).build())  # type: ignore[arg-type]
    b = _sweep(family_member("jawcrimp", 3).build())  # type: ignore[arg-type]
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_reset_returns_to_the_first_run() -> None:
    plant = make_jawcrimp_plant()
    first = _sweep(plant)
    plant.reset()
    again = _sweep(plant)
    assert np.array_equal(first[0], again[0]) and np.array_equal(first[1], again[1])


def test_the_dead_zone_moves_the_tip_little_and_engagement_moves_it_much() -> None:
    plant = make_jawcrimp_plant()
    tip, _ = drive_knob(plant, 0, ramp_deg(0.0, 15.0))
    assert abs(tip[-1]) < 3.0
    tip, _ = drive_knob(plant, 0, ramp_deg(15.0, 75.0))
    assert tip[-1] > 50.0


def test_the_tip_holds_after_a_reversal_then_releases() -> None:
    plant = make_jawcrimp_plant()
    tip, torque = drive_knob(plant, 0, ramp_deg(0.0, 80.0))
    top, loaded = tip[-1], torque[-1]
    tip, torque = drive_knob(plant, 0, ramp_deg(80.0, 76.0))
    assert abs(tip[-1] - top) < 2.0 and torque[-1] < 0.7 * loaded
    tip, _ = drive_knob(plant, 0, ramp_deg(76.0, 40.0))
    assert tip[-1] < top - 20.0


def test_the_bend_is_symmetric_on_a_symmetric_knob() -> None:
    plant = make_jawcrimp_plant(knobs=[{"heart_moment_Nmm": 0.0}, {"heart_moment_Nmm": 0.0}])
    up, _ = drive_knob(plant, 0, ramp_deg(0.0, 70.0))
    plant.reset()
    down, _ = drive_knob(plant, 0, ramp_deg(0.0, -70.0))
    assert up[-1] == pytest.approx(-down[-1], abs=1e-6)


def test_energy_a_closed_loop_costs_work() -> None:
    plant = make_jawcrimp_plant()
    path = np.concatenate([ramp_deg(0.0, 80.0), ramp_deg(80.0, -80.0), ramp_deg(-80.0, 0.0)])
    _, torque = drive_knob(plant, 0, path)
    work_J = float(np.sum(torque[1:] * np.diff(np.radians(path))))
    assert work_J > 0.0


def test_loading_one_knob_shortens_the_shaft_and_widens_the_other_dead_zone() -> None:
    def engaged_at(other_deg: float) -> float:
        plant = make_jawcrimp_plant()
        drive_knob(plant, 1, ramp_deg(0.0, other_deg))
        path = ramp_deg(0.0, 50.0)
        tip, _ = drive_knob(plant, 0, path, other_deg=other_deg)
        return float(path[np.argmax(tip > 3.0)])

    assert engaged_at(80.0) > engaged_at(0.0) + 1.0
    plant = make_jawcrimp_plant()
    drive_knob(plant, 1, ramp_deg(0.0, 80.0))
    assert plant.shortening_mm > 0.2


def test_a_held_pull_creeps_the_crimp_and_lets_the_tip_back() -> None:
    plant = make_jawcrimp_plant(knobs=[{"heart_moment_Nmm": 0.0}, {"heart_moment_Nmm": 0.0}])
    tip, _ = drive_knob(plant, 0, ramp_deg(0.0, 80.0))
    held, _ = drive_knob(plant, 0, np.full(round(60.0 / STEP_S), 80.0))
    assert plant.crept_mm[0][0] > 0.01 > 10.0 * plant.crept_mm[0][1]
    assert held[-1] < tip[-1] - 0.1


def test_the_heart_moves_a_free_tip_a_little_and_does_not_drift_it() -> None:
    plant = make_jawcrimp_plant()
    tip, _ = drive_knob(plant, 0, np.zeros(round(3.0 / STEP_S)))
    assert 0.05 < float(np.ptp(tip)) < 2.0
    assert abs(float(np.mean(tip[-round(1.0 / 1.15 / STEP_S):]))) < 0.1


def test_more_slack_mid_run_widens_the_dead_zone_and_stays_through_reset() -> None:
    def engaged_at(plant: JawCrimpPlant) -> float:
        path = ramp_deg(0.0, 50.0)
        tip, _ = drive_knob(plant, 0, path)
        return float(path[np.argmax(tip > 3.0)])

    plant = make_jawcrimp_plant()
    before = engaged_at(plant)
    plant.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    plant.reset()
    assert engaged_at(plant) == pytest.approx(before + math.degrees(0.5 / 6.5), abs=0.5)


def test_unknown_reshapes_are_refused() -> None:
    with pytest.raises(PlantLoadError, match="jawcrimp cannot reshape stiffness"):
        make_jawcrimp_plant().reshape(stiffness=2.0)
    with pytest.raises(PlantLoadError, match="sheath_curvature_deg must be >= 0"):
        make_jawcrimp_plant().reshape(sheath_curvature_deg=-5.0)


def test_jawcrimp_is_registered_after_archwave_and_held_out() -> None:
    names = list(PLANT_SPECS)
    assert names.index("jawcrimp") == names.index("archwave") + 1
    assert PLANT_ROLE["jawcrimp"] == "held-out"
    assert isinstance(family_member("jawcrimp", 101).build(), JawCrimpPlant)
    assert set(SCATTER["jawcrimp"]) <= set(family_member("jawcrimp", 0).params["knobs"][0])


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"knobs": [{"spider": 1.0}, {}]}, "unknown jawcrimp knob constants: spider"),
        ({"knobs": [{}]}, "jawcrimp takes 2 knobs"),
        ({"knobs": [{"tendon_stiffness_N": 0.0}, {}]}, "tendon_stiffness_N must be > 0"),
        ({"knobs": [{}, {"sheath_friction": -0.1}]}, "sheath_friction must be >= 0"),
        ({"knobs": [{"node_share": 1.0}, {}]}, "node_share must be in"),
        ({"knobs": [{"idler_friction": 0.6}, {}]}, "idler_friction must be < 0.5"),
        ({"sheath_curvature_deg": -10.0}, "sheath_curvature_deg must be >= 0"),
    ],
)
def test_bad_constants_are_refused_with_one_clear_line(kwargs: dict[str, object],
                                                       message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        make_jawcrimp_plant(**kwargs)  # type: ignore[arg-type]


def test_bad_step_input_is_refused() -> None:
    with pytest.raises(ValueError, match="dt_s must be >= 0"):
        make_jawcrimp_plant().step(-0.001, np.zeros(2))
    with pytest.raises(ValueError, match="knob_deg must be 2 finite angles"):
        make_jawcrimp_plant().step(0.004, np.array([math.nan, 0.0]))
