"""The archwave plant (blind in session 19, held out from session 20): laws, registration."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.plant_drive import STEP_S, drive_knob, ramp_deg

from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import Plant, PlantLoadError, load_plant
from simrig.plants.archwave import ArchWavePlant, make_archwave_plant
from simrig.plants.archwave.laws import (
    flex_twist,
    flex_z_after,
    kinematic_error_rad,
    path_slack_mm,
    tensioner_tension,
    winding_rise_K,
)

SPEC = "simrig.plants.archwave:make_archwave_plant"


def test_the_tensioner_holds_a_soft_floor_then_the_tendon_takes_over() -> None:
    floor, rate = tensioner_tension(1.0, 2.0, 0.4, 0.05, 5.0, 6.0)
    assert floor == pytest.approx(0.45) and rate == pytest.approx(0.05)
    loaded, stiff = tensioner_tension(3.0, 2.0, 0.4, 0.05, 5.0, 6.0)
    assert loaded == pytest.approx(0.5 + 6.0) and stiff == pytest.approx(6.0)
    assert tensioner_tension(-8.0, 2.0, 0.4, 0.05, 5.0, 6.0) == (0.0, 0.0)


def test_a_bend_frees_the_inner_tendon_and_takes_up_the_outer() -> None:
    inner = path_slack_mm(0.0, ((90.0, 0.0),), 0.1, 0.3)
    outer = path_slack_mm(180.0, ((90.0, 0.0),), 0.1, 0.3)
    assert inner == pytest.approx(math.pi / 2 * 0.4)
    assert outer == pytest.approx(math.pi / 2 * -0.2)


def test_the_flexspline_twist_is_hysteretic_and_stiffens() -> None:
    z_max = math.radians(0.5)
    assert flex_z_after(0.0, 1.0, z_max) == pytest.approx(z_max)
    assert flex_z_after(z_max, -0.2 * z_max, z_max) == pytest.approx(0.8 * z_max)
    up, z = flex_twist(0.1, 0.0, 0.0, 10.0, 2000.0, 0.6, z_max)
    more, _ = flex_twist(0.2, up, z, 10.0, 2000.0, 0.6, z_max)
    assert more - up < up  # stiffer under load
    back, _ = flex_twist(0.1, more, _, 10.0, 2000.0, 0.6, z_max)
    assert back > up  # lost motion: unloading to the same torque leaves more twist


def test_the_kinematic_error_repeats_twice_per_output_revolution() -> None:
    assert kinematic_error_rad(0.3, 0.2, 10.0) == pytest.approx(
        kinematic_error_rad(0.3 + math.pi, 0.2, 10.0))
    assert abs(kinematic_error_rad(0.3 + math.pi / 2, 0.2, 10.0)
               + kinematic_error_rad(0.3, 0.2, 10.0)) < 1e-12


def test_the_winding_warms_towards_power_times_resistance() -> None:
    assert winding_rise_K(0.0, 1e6, 1.0, 24.0, 240.0) == pytest.approx(24.0)
    assert winding_rise_K(0.0, 240.0, 1.0, 24.0, 240.0) == pytest.approx(24.0 * (1 - 1 / math.e))


def test_the_plant_follows_the_protocol_and_loads_by_name() -> None:
    plant = load_plant(SPEC)
    assert isinstance(plant, Plant) and isinstance(plant, ArchWavePlant)


def test_same_inputs_give_the_same_outputs() -> None:
    path = ramp_deg(0.0, 80.0)
    a = drive_knob(make_archwave_plant(), 0, path)
    b = drive_knob(make_archwave_plant(), 0, path)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_reset_returns_to_the_first_run() -> None:
    plant = make_archwave_plant()
    path = np.concatenate([ramp_deg(0.0, 70.0), ramp_deg(70.0, -40.0)])
    first = drive_knob(plant, 1, path)
    plant.reset()
    assert np.array_equal(drive_knob(plant, 1, path)[0], first[0])


def test_the_dead_zone_moves_the_tip_little_and_engagement_moves_it_much() -> None:
    tip, _ = drive_knob(make_archwave_plant(), 0, ramp_deg(0.0, 90.0))
    path = ramp_deg(0.0, 90.0)
    early = tip[np.searchsorted(path, 10.0)] - tip[0]
    assert abs(early) < 5.0 and tip[-1] > 60.0


def test_the_tip_holds_after_a_reversal_then_releases() -> None:
    path = np.concatenate([ramp_deg(0.0, 90.0), ramp_deg(90.0, 0.0)])
    tip, _ = drive_knob(make_archwave_plant(), 0, path)
    top = int(np.argmax(path))
    assert tip[top + 50] == pytest.approx(tip[top], abs=1.0)  # 4 deg of knob back: held
    assert tip[-1] < tip[top] - 40.0


def test_energy_a_closed_loop_costs_work() -> None:
    path = np.concatenate([ramp_deg(0.0, 80.0), ramp_deg(80.0, -80.0), ramp_deg(-80.0, 0.0)])
    _, torque = drive_knob(make_archwave_plant(), 0, path)
    work_J = float(np.sum(torque[1:] * np.radians(np.diff(path))))
    assert work_J > 0.0


def test_the_other_knobs_bend_adds_wrap_and_so_friction() -> None:
    path = ramp_deg(0.0, 80.0)
    plain = make_archwave_plant()
    bent = make_archwave_plant()
    drive_knob(bent, 1, ramp_deg(0.0, 80.0))
    _, tau_plain = drive_knob(plain, 0, path)
    _, tau_bent = drive_knob(bent, 0, path, other_deg=80.0)
    assert tau_bent[-1] > tau_plain[-1]


def test_a_longer_arch_bends_the_tip_less_and_asks_more_torque_per_tip_angle() -> None:
    path = ramp_deg(0.0, 90.0)
    tip_s, tau_s = drive_knob(make_archwave_plant(), 0, path)
    tip_c, tau_c = drive_knob(make_archwave_plant(sheath_curvature_deg=120.0), 0, path)
    assert tip_c[-1] < tip_s[-1]
    assert np.interp(40.0, tip_c, tau_c) > np.interp(40.0, tip_s, tau_s)


def test_more_slack_mid_run_widens_the_dead_zone() -> None:
    path = ramp_deg(0.0, 45.0)
    plain, slackened = make_archwave_plant(), make_archwave_plant()
    slackened.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    tip_plain, _ = drive_knob(plain, 0, path)
    tip_slack, _ = drive_knob(slackened, 0, path)
    assert tip_slack[-1] < tip_plain[-1] - 2.0


def test_a_weaker_motor_constant_reads_as_more_load() -> None:
    path = ramp_deg(0.0, 80.0)
    _, nominal = drive_knob(make_archwave_plant(), 0, path)
    _, weak = drive_knob(make_archwave_plant(knobs=[{"torque_constant_ratio": 0.9}, {}]), 0, path)
    assert weak[-1] == pytest.approx(nominal[-1] / 0.9, rel=1e-9)


def test_unknown_reshapes_are_refused() -> None:
    with pytest.raises(PlantLoadError, match="cannot reshape stiffness"):
        make_archwave_plant().reshape(stiffness=2.0)


def test_archwave_keeps_its_place_after_warmgear_and_is_held_out() -> None:
    names = list(PLANT_SPECS)
    assert names.index("archwave") == names.index("warmgear") + 1  # its units' seeds hold
    assert PLANT_ROLE["archwave"] == "held-out"
    assert isinstance(family_member("archwave", 101).build(), ArchWavePlant)
    assert set(SCATTER["archwave"]) <= set(family_member("archwave", 0).params["knobs"][0])


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"knobs": [{"spring": 1.0}, {}]}, "unknown archwave knob constants: spring"),
        ({"knobs": [{}]}, "archwave takes 2 knobs"),
        ({"knobs": [{"tendon_stiffness_N": 0.0}, {}]}, "tendon_stiffness_N must be > 0"),
        ({"knobs": [{}, {"sheath_friction": -0.1}]}, "sheath_friction must be >= 0"),
        ({"knobs": [{"flex_elastic_share": 1.5}, {}]}, "flex_elastic_share must be in"),
        ({"knobs": [{"tensioner_reserve_mm": 50.0}, {}]}, "tensioner_reserve_mm must not"),
        ({"sheath_curvature_deg": -10.0}, "sheath_curvature_deg must be >= 0"),
        ({"arch_deg": 400.0}, "arch_deg must be in"),
        ({"oven_C": 40.0}, "unknown archwave path constants: oven_C"),
    ],
)
def test_bad_constants_are_refused_with_one_clear_line(kwargs: dict[str, object],
                                                       message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        make_archwave_plant(**kwargs)  # type: ignore[arg-type]


def test_bad_step_input_is_refused() -> None:
    with pytest.raises(ValueError, match="dt_s must be >= 0"):
        make_archwave_plant().step(-0.001, np.zeros(2))
    with pytest.raises(ValueError, match="knob_deg must be 2 finite angles"):
        make_archwave_plant().step(STEP_S, np.array([np.nan, 0.0]))
