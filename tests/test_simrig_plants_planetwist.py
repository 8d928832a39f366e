"""The planetwist plant: a planetary handle stage, twist-coupled strands, blood flow on the tip."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.plant_drive import STEP_S, drive_knob, ramp_deg

from simrig.analysis import measure_dead_zone_backlash
from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import PlantLoadError, load_plant
from simrig.plants.planetwist import PlanetTwistPlant, make_planetwist_plant
from simrig.plants.planetwist.laws import (
    gear_twist_rad,
    knob_constants,
    proximal_give_mm,
    proximal_tension_N,
    strand_stretch,
)
from simrig.plants.planetwist.params import NOMINAL_KNOBS
from simrig.report import run_sweep

SPEC = "simrig.plants.planetwist:make_planetwist_plant"
K = knob_constants(NOMINAL_KNOBS[0])


def _cycle(plant: PlanetTwistPlant, knob: int = 0, amp_deg: float = 80.0
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    path = np.concatenate([ramp_deg(0.0, amp_deg), ramp_deg(amp_deg, -amp_deg),
                           ramp_deg(-amp_deg, 0.0)])
    tip, torque = drive_knob(plant, knob, path)
    return path, tip, torque


def test_each_planet_takes_load_only_after_its_position_error_closes() -> None:
    low = gear_twist_rad(K, 1.0)[1]
    high = gear_twist_rad(K, 1e4)[1]
    assert high < low  # three planets share a large load: the stage is stiffer
    assert gear_twist_rad(K, 200.0)[0] > gear_twist_rad(K, 100.0)[0]


def test_proximal_tension_inverts_the_proximal_give() -> None:
    for tension_N in (0.5, 3.0, 20.0, 60.0):
        give_mm, _ = proximal_give_mm(K, tension_N)
        assert proximal_tension_N(K, give_mm) == pytest.approx(tension_N, rel=1e-9)
    assert proximal_tension_N(K, -0.1) == 0.0


def test_a_strand_free_to_untwist_is_softer_than_a_held_one() -> None:
    held = strand_stretch(K, 10.0, 0.0)  # trial from an untwisted strand: the swivel slides
    assert held[2] != 0.0  # the swivel turned
    assert held[1] > K.distal_mm / K.ea_N  # and the strand is softer than EA


def test_at_rest_the_tip_is_straight_but_for_the_flow_and_the_knobs_unloaded() -> None:
    plant = make_planetwist_plant()
    step = plant.step(STEP_S, np.zeros(2))
    assert np.all(np.abs(step.tip_deg) < 1.0)
    assert np.all(step.knob_torque_Nm == 0.0)


def test_the_loop_has_a_dead_zone_and_a_backlash_in_the_probes_range() -> None:
    record = run_sweep(make_planetwist_plant(), 0)
    found = measure_dead_zone_backlash(record.knob_deg, record.tip_deg)
    assert 10.0 < found.dead_zone_pos_deg < 40.0 and 10.0 < -found.dead_zone_neg_deg < 40.0
    assert 5.0 < found.backlash_pos_deg < 25.0 and 5.0 < found.backlash_neg_deg < 25.0


def test_after_a_reversal_the_tip_holds_while_the_torque_falls() -> None:
    plant = make_planetwist_plant()
    tip_up, torque_up = drive_knob(plant, 0, ramp_deg(0.0, 80.0))
    tip_back, torque_back = drive_knob(plant, 0, ramp_deg(80.0, 74.0))
    assert abs(tip_back[-1] - tip_up[-1]) < 1.0
    assert abs(torque_back[-1]) < 0.2 * abs(torque_up[-1])


def test_a_closed_knob_cycle_dissipates_energy() -> None:
    path, _, torque = _cycle(make_planetwist_plant())
    work_J = float(np.sum(0.5 * (torque[1:] + torque[:-1]) * np.radians(np.diff(path))))
    assert work_J > 0.0


def test_more_slack_widens_the_dead_zone() -> None:
    plant = make_planetwist_plant()
    tip_before, _ = drive_knob(plant, 0, ramp_deg(0.0, 40.0))
    plant.reset()
    plant.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    tip_after, _ = drive_knob(plant, 0, ramp_deg(0.0, 40.0))
    assert tip_after[-1] < tip_before[-1] - 3.0


def test_the_other_planes_bend_stiffens_the_section() -> None:
    alone, _ = drive_knob(make_planetwist_plant(), 0, ramp_deg(0.0, 70.0))
    plant = make_planetwist_plant()
    drive_knob(plant, 1, ramp_deg(0.0, 70.0))
    coupled, _ = drive_knob(plant, 0, ramp_deg(0.0, 70.0), other_deg=70.0)
    assert coupled[-1] < alone[-1] - 0.5


def test_a_unit_is_the_same_every_time_and_differs_from_another() -> None:
    path = np.concatenate([ramp_deg(0.0, 70.0), ramp_deg(70.0, -30.0)])
    a, _ = drive_knob(family_member("planetwist", 101).build(), 0, path)
    b, _ = drive_knob(family_member("planetwist", 101).build(), 0, path)
    c, _ = drive_knob(family_member("planetwist", 102).build(), 0, path)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_planetwist_is_registered_and_held_out() -> None:
    assert "planetwist" in PLANT_SPECS
    assert PLANT_ROLE["planetwist"] == "held-out"
    assert isinstance(family_member("planetwist", 101).build(), PlanetTwistPlant)
    assert set(SCATTER["planetwist"]) <= set(family_member("planetwist", 0).params["knobs"][0])
    assert isinstance(load_plant(SPEC), PlanetTwistPlant)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"knobs": [{"planet": 1.0}, {}]}, "unknown planetwist knob constants: planet"),
        ({"knobs": [{}]}, "planetwist takes 2 knobs"),
        ({"knobs": [{"tendon_stiffness_N": 0.0}, {}]}, "tendon_stiffness_N must be > 0"),
        ({"knobs": [{}, {"sheath_friction": -0.1}]}, "sheath_friction must be >= 0"),
        ({"knobs": [{"gear_efficiency": 1.2}, {}]}, "gear_efficiency must be in"),
        ({"knobs": [{"sheath_friction": 0.5}, {}]}, "the lumped contact would lock"),
        ({"sheath_curvature_deg": -10.0}, "sheath_curvature_deg must be >= 0"),
    ],
)
def test_bad_constants_are_refused_with_one_clear_line(kwargs: dict[str, object],
                                                       message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        make_planetwist_plant(**kwargs)  # type: ignore[arg-type]


def test_bad_step_input_and_reshape_are_refused() -> None:
    with pytest.raises(ValueError, match="dt_s must be >= 0"):
        make_planetwist_plant().step(-0.001, np.zeros(2))
    with pytest.raises(ValueError, match="knob_deg must be 2 finite angles"):
        make_planetwist_plant().step(STEP_S, np.array([math.nan, 0.0]))
    with pytest.raises(PlantLoadError, match="cannot reshape wrap"):
        make_planetwist_plant().reshape(wrap=1.0)
