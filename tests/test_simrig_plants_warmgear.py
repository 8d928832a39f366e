"""The warmgear plant (blind in session 18): laws, behaviours, registration, refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.plant_drive import STEP_S, drive_knob, ramp_deg

from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import Plant, PlantLoadError, load_plant
from simrig.plants.warmgear import NOMINAL_KNOBS, WarmGearPlant, make_warmgear_plant
from simrig.plants.warmgear.laws import (
    film_after,
    mesh_loss,
    mesh_stiffness,
    shaft_temperature_C,
    viscosity_factor,
)

SPEC = "simrig.plants.warmgear:make_warmgear_plant"
DT = STEP_S



def test_the_shaft_warms_from_room_towards_body_temperature() -> None:
    assert shaft_temperature_C(0.0, 22.0, 37.0, 150.0) == pytest.approx(22.0)
    assert shaft_temperature_C(150.0, 22.0, 37.0, 150.0) == pytest.approx(37.0 - 15.0 / math.e)
    assert shaft_temperature_C(3000.0, 22.0, 37.0, 150.0) == pytest.approx(37.0)


def test_the_film_is_thinner_when_warm() -> None:
    assert viscosity_factor(37.0, 22.0) == pytest.approx(0.69 / 0.95, rel=0.05)


def test_a_loaded_contact_at_rest_squeezes_its_film_and_sliding_rebuilds_it() -> None:
    at_rest = film_after(1.0, 10.0, 0.0, 3.0, 3.0, 1.5, 1e9)
    assert at_rest == pytest.approx(1.0 / math.sqrt(3.0))
    assert film_after(at_rest, 10.0, 5.0, 1.0, 3.0, 1.5, 1e9) > at_rest
    assert film_after(0.5, 0.0, 0.0, 1.0, 3.0, 1.5, 1e9) == pytest.approx(0.5)


def test_the_mesh_is_stiffest_with_two_tooth_pairs_and_loses_nothing_at_the_pitch_point() -> None:
    assert mesh_stiffness(-0.5, 100.0, 0.2) > mesh_stiffness(0.0, 100.0, 0.2)
    assert mesh_loss(0.0, 0.2, 15.0, 20.0) == 0.0
    assert mesh_loss(0.4, 0.2, 15.0, 20.0) > mesh_loss(0.1, 0.2, 15.0, 20.0)


def test_the_plant_follows_the_protocol_and_loads_by_name() -> None:
    plant = load_plant(SPEC)
    assert isinstance(plant, Plant) and isinstance(plant, WarmGearPlant)


def test_same_inputs_give_the_same_outputs() -> None:
    path = ramp_deg(0.0, 80.0)
    a = drive_knob(make_warmgear_plant(), 0, path)
    b = drive_knob(make_warmgear_plant(), 0, path)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_reset_returns_to_the_straight_unloaded_cold_state() -> None:
    plant = make_warmgear_plant()
    drive_knob(plant, 0, ramp_deg(0.0, 80.0))
    plant.reset()
    assert plant.t_s == 0.0 and plant.temperature_C == pytest.approx(22.0)
    assert np.all(plant.tensions_N() == 0.0)
    assert np.allclose(plant.step(DT, np.zeros(2)).tip_deg, 0.0)


def test_inside_the_slack_the_tip_stays_straight_and_only_the_handle_loads() -> None:
    """The knob seal, then (past the gear's play) the drum bearing through the mesh."""
    tip, torque = drive_knob(make_warmgear_plant(), 0, ramp_deg(0.0, 8.0))
    p = NOMINAL_KNOBS[0]
    handle_Nm = p.handle_friction_Nm + 1.2 * p.drum_friction_Nmm / 1000.0 * (
        p.pinion_teeth / p.drum_teeth)
    assert np.max(np.abs(tip)) == 0.0
    assert np.max(np.abs(torque)) <= handle_Nm
    assert np.max(np.abs(torque)) > p.handle_friction_Nm


def test_pulling_further_bends_the_tip_further_and_less_than_the_geometry_allows() -> None:
    path = ramp_deg(0.0, 90.0)
    tip, _ = drive_knob(make_warmgear_plant(), 0, path)
    p = NOMINAL_KNOBS[0]
    geometric = 90.0 * p.pulley_radius_mm * p.pinion_teeth / p.drum_teeth / p.tendon_offset_mm
    assert tip[-1] > tip[len(tip) // 2] > 0.0
    assert tip[-1] < geometric


def test_a_closed_knob_cycle_dissipates_energy() -> None:
    path = np.concatenate([ramp_deg(0.0, 90.0), ramp_deg(90.0, -90.0), ramp_deg(-90.0, 0.0)])
    _, torque = drive_knob(make_warmgear_plant(), 0, path)
    work_J = float(np.sum(torque[1:] * np.diff(np.radians(path))))
    assert work_J > 0.0


def test_the_tip_holds_after_a_reversal_then_returns() -> None:
    plant = make_warmgear_plant()
    tip_up, _ = drive_knob(plant, 0, ramp_deg(0.0, 80.0))
    tip_back, _ = drive_knob(plant, 0, ramp_deg(80.0, 0.0))
    held = tip_back[: len(tip_back) // 40]  # the first 2 deg of knob travel back
    # it does not return yet; the film's shear, no longer dragging, lets it settle on (0.5 deg
    # after a 20 deg/s pull on the nominal unit)
    assert np.all(held >= tip_up[-1]) and np.all(held < tip_up[-1] + 1.0)
    assert tip_back[-1] < tip_up[-1] - 40.0


def test_warming_in_the_body_takes_up_slack_and_narrows_the_dead_zone() -> None:
    cold, warm = make_warmgear_plant(), make_warmgear_plant()
    for _ in range(int(600.0 / 0.1)):
        warm.step(0.1, np.zeros(2))
    path = ramp_deg(0.0, 30.0)
    tip_cold, _ = drive_knob(cold, 0, path)
    tip_warm, _ = drive_knob(warm, 0, path)
    assert warm.temperature_C > 36.0
    assert tip_warm[-1] > tip_cold[-1] + 1.0


def test_the_right_left_plane_is_the_softer_one() -> None:
    assert NOMINAL_KNOBS[1].bend_stiffness_Nm_per_rad < NOMINAL_KNOBS[0].bend_stiffness_Nm_per_rad
    a, _ = drive_knob(make_warmgear_plant(knobs=[{}, {}]), 0, ramp_deg(0.0, 70.0))
    soft = NOMINAL_KNOBS[1].bend_stiffness_Nm_per_rad
    b, _ = drive_knob(make_warmgear_plant(knobs=[{"bend_stiffness_Nm_per_rad": soft}, {}]), 0,
                  ramp_deg(0.0, 70.0))
    assert b[-1] > a[-1]


def test_bending_the_other_plane_adds_friction_to_this_one() -> None:
    path = ramp_deg(0.0, 80.0)
    plain = make_warmgear_plant()
    _, alone = drive_knob(plain, 0, path)
    bent = make_warmgear_plant()
    drive_knob(bent, 1, ramp_deg(0.0, 80.0))
    _, coupled = drive_knob(bent, 0, path, other_deg=80.0)
    assert coupled[-1] > alone[-1]


def test_a_curved_shaft_needs_more_torque_and_bends_the_tip_less() -> None:
    path = ramp_deg(0.0, 90.0)
    tip_s, tau_s = drive_knob(make_warmgear_plant(), 0, path)
    tip_c, tau_c = drive_knob(make_warmgear_plant(sheath_curvature_deg=120.0), 0, path)
    assert tau_c[-1] > tau_s[-1] and tip_c[-1] < tip_s[-1]


def test_more_slack_mid_run_widens_the_dead_zone() -> None:
    path = ramp_deg(0.0, 45.0)
    plain, slackened = make_warmgear_plant(), make_warmgear_plant()
    slackened.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    tip_plain, _ = drive_knob(plain, 0, path)
    tip_slack, _ = drive_knob(slackened, 0, path)
    assert tip_slack[-1] < tip_plain[-1] - 2.0


def test_unknown_reshapes_are_refused() -> None:
    with pytest.raises(PlantLoadError, match="cannot reshape stiffness"):
        make_warmgear_plant().reshape(stiffness=2.0)


def test_warmgear_is_registered_after_ratestate_and_held_out() -> None:
    names = list(PLANT_SPECS)
    assert names.index("warmgear") == names.index("ratestate") + 1
    assert PLANT_ROLE["warmgear"] == "held-out"
    assert isinstance(family_member("warmgear", 101).build(), WarmGearPlant)
    assert set(SCATTER["warmgear"]) <= set(family_member("warmgear", 0).params["knobs"][0])


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"knobs": [{"spring": 1.0}, {}]}, "unknown warmgear knob constants: spring"),
        ({"knobs": [{}]}, "warmgear takes 2 knobs"),
        ({"knobs": [{"tendon_stiffness_N": 0.0}, {}]}, "tendon_stiffness_N must be > 0"),
        ({"knobs": [{}, {"sheath_friction": -0.1}]}, "sheath_friction must be >= 0"),
        ({"knobs": [{"film_friction": 0.9}, {}]}, "film_friction must not exceed"),
        ({"knobs": [{"mesh_ripple": 1.0}, {}]}, "mesh_ripple must be in"),
        ({"sheath_curvature_deg": -10.0}, "sheath_curvature_deg must be >= 0"),
        ({"warm_time_s": 0.0}, "warm_time_s must be > 0"),
        ({"oven_C": 40.0}, "unknown warmgear shaft constants: oven_C"),
    ],
)
def test_bad_constants_are_refused_with_one_clear_line(kwargs: dict[str, object],
                                                       message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        make_warmgear_plant(**kwargs)  # type: ignore[arg-type]


def test_bad_step_input_is_refused() -> None:
    with pytest.raises(ValueError, match="dt_s must be >= 0"):
        make_warmgear_plant().step(-0.001, np.zeros(2))
    with pytest.raises(ValueError, match="knob_deg must be 2 finite angles"):
        make_warmgear_plant().step(DT, np.array([np.nan, 0.0]))
