"""The seventeenth plant, notchclutch (written blind in session 24): a slip clutch between knob and
drum, aramid tendons over a lumen contact on a soaking hydrophilic liner, a notched steel section
whose notches close, a tip rubbing on the oesophageal wall."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.plant_drive import STEP_S, drive_knob, ramp_deg

from simrig.analysis import measure_dead_zone_backlash
from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import PlantLoadError, load_plant
from simrig.plants.notchclutch import NotchClutchPlant, make_notchclutch_plant
from simrig.plants.notchclutch.laws import (
    liner_friction,
    notch_moment_Nmm,
    tendon_contact,
    toe_force_N,
    toe_stretch_mm,
)
from simrig.report import run_sweep

SPEC = "simrig.plants.notchclutch:make_notchclutch_plant"


def _cycle(plant: NotchClutchPlant, knob: int = 0, amp_deg: float = 80.0
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    path = np.concatenate([ramp_deg(0.0, amp_deg), ramp_deg(amp_deg, -amp_deg),
                           ramp_deg(-amp_deg, 0.0)])
    tip, torque = drive_knob(plant, knob, path)
    return path, tip, torque


def test_the_braid_toe_is_quadratic_then_linear_and_inverts() -> None:
    assert toe_force_N(10.0, 0.4, -1.0) == 0.0
    assert toe_force_N(10.0, 0.4, 0.2) == pytest.approx(10.0 * 0.04 / 0.8)
    assert toe_force_N(10.0, 0.4, 1.0) == pytest.approx(10.0 * 0.8)
    for f in (0.3, 2.0, 8.0):
        assert toe_force_N(10.0, 0.4, toe_stretch_mm(10.0, 0.4, f)) == pytest.approx(f)


def test_the_lumen_contact_sticks_inside_the_capstan_ratio_and_slides_onto_it() -> None:
    # stuck: 30 mm drawn, contact where the tensions are within a ratio of 2
    contact, t1, t2 = tendon_contact(30.0, 0.0, 29.5, 29.0, 10.0, 10.0, 0.0, 2.0, 0.0)
    assert contact == 29.5 and t2 <= 2.0 * t1 and t1 <= 2.0 * t2
    # drawn further: the contact slides toward the handle until t1 = 2 t2
    contact, t1, t2 = tendon_contact(33.0, 0.0, 29.5, 29.0, 10.0, 10.0, 0.0, 2.0, 0.0)
    assert contact > 29.5 and t1 == pytest.approx(2.0 * t2)
    # let go: the section pulls the tendon back until t2 = 2 t1
    contact, t1, t2 = tendon_contact(29.2, 0.0, 29.5, 29.0, 10.0, 10.0, 0.0, 2.0, 0.0)
    assert contact < 29.5 and t1 > 0.0 and t2 == pytest.approx(2.0 * t1)


def test_the_liner_slides_easier_once_soaked_and_once_its_film_carries() -> None:
    dry = liner_friction(0.1, 1.5, 40.0, 0.0, 0.2, 0.0, 0.8)
    soaked = liner_friction(0.1, 1.5, 40.0, 600.0, 0.2, 0.0, 0.8)
    carried = liner_friction(0.1, 1.5, 40.0, 600.0, 0.2, 5.0, 0.8)
    assert dry == pytest.approx(0.15 * 1.2)
    assert dry > soaked > carried > 0.1


def test_closing_notches_stiffen_the_section_and_the_other_planes_bend_closes_them() -> None:
    k, close, width = 30.0, math.radians(135.0), math.radians(12.0)
    open_m = notch_moment_Nmm(k, 1.0, 1.0, close, width, 6.0)
    assert open_m == pytest.approx(30.0, rel=0.01)
    closed = notch_moment_Nmm(k, 2.6, 2.6, close, width, 6.0)
    assert closed > 1.5 * k * 2.6
    assert notch_moment_Nmm(k, 1.5, math.hypot(1.5, 1.8), close, width, 6.0) > (
        notch_moment_Nmm(k, 1.5, 1.5, close, width, 6.0))


def test_at_rest_the_tip_is_straight_and_inside_the_slack_the_knob_pulls_nothing() -> None:
    plant = make_notchclutch_plant()
    tip, torque = drive_knob(plant, 0, ramp_deg(0.0, 8.0))
    assert np.max(np.abs(tip)) < 0.5
    assert np.max(np.abs(torque)) <= plant.knobs[0].handle_friction_Nm + 1e-9


def test_the_loop_has_a_dead_zone_and_a_backlash() -> None:
    rec = run_sweep(make_notchclutch_plant(), 0, dt_s=STEP_S)
    m = measure_dead_zone_backlash(rec.knob_deg, rec.tip_deg)
    assert 10.0 < m.dead_zone_pos_deg < 25.0 and -25.0 < m.dead_zone_neg_deg < -10.0
    assert 5.0 < m.backlash_pos_deg < 30.0 and 5.0 < m.backlash_neg_deg < 30.0


def test_after_a_reversal_the_tip_holds_while_the_torque_falls() -> None:
    plant = make_notchclutch_plant()
    drive_knob(plant, 0, ramp_deg(0.0, 80.0))
    tip_top, tau_top = drive_knob(plant, 0, np.array([80.0]))
    tip, tau = drive_knob(plant, 0, ramp_deg(80.0, 76.0))
    assert abs(tip[-1] - tip_top[0]) < 1.0
    assert tau[-1] < 0.5 * tau_top[0]


def test_a_closed_knob_cycle_dissipates_energy() -> None:
    path, _, torque = _cycle(make_notchclutch_plant())
    work = float(np.sum(torque[1:] * np.diff(np.radians(path))))
    assert work > 0.0


def test_more_slack_widens_the_dead_zone() -> None:
    path = ramp_deg(0.0, 40.0)
    plain, _ = drive_knob(make_notchclutch_plant(), 0, path)
    loose = make_notchclutch_plant()
    loose.reshape(slack_delta_mm=((0.5, 0.5), (0.0, 0.0)))
    slack, _ = drive_knob(loose, 0, path)
    assert path[np.argmax(slack > 1.0)] > path[np.argmax(plain > 1.0)] + 2.0


def test_an_overload_slips_the_clutch_and_caps_the_torque() -> None:
    weak = make_notchclutch_plant([{"clutch_capacity_Nmm": 150.0}, {}])
    tip, torque = drive_knob(weak, 0, ramp_deg(0.0, 90.0))
    kinetic = 150.0 * weak.knobs[0].clutch_kinetic_ratio / 1000.0
    assert weak.clutch_slip_deg[0] > 5.0
    assert np.max(torque) <= 0.150 + weak.knobs[0].handle_friction_Nm + 1e-6
    late = torque[-100:] - weak.knobs[0].handle_friction_Nm
    assert np.all(late >= 0.95 * kinetic)  # slipping, or stuck again and loading up
    strong, _ = drive_knob(make_notchclutch_plant(), 0, ramp_deg(0.0, 90.0))
    assert tip[-1] < strong[-1] - 5.0


def test_a_freshly_inserted_catheter_has_more_friction_than_a_soaked_one() -> None:
    fresh = make_notchclutch_plant()
    _, _, tau_fresh = _cycle(fresh)
    soaked = make_notchclutch_plant()
    drive_knob(soaked, 0, np.zeros(round(300.0 / STEP_S)))
    _, _, tau_soaked = _cycle(soaked)
    assert np.max(tau_fresh) > 1.05 * np.max(tau_soaked)


def test_the_other_planes_bend_changes_this_planes_loop() -> None:
    path = ramp_deg(0.0, 80.0)
    alone, _ = drive_knob(make_notchclutch_plant(), 0, path)
    bent = make_notchclutch_plant()
    drive_knob(bent, 1, ramp_deg(0.0, 90.0))
    coupled, _ = drive_knob(bent, 0, path, other_deg=90.0)
    assert abs(coupled[-1] - alone[-1]) > 2.0


def test_the_coupling_keyword_takes_up_the_tendons_by_the_other_planes_bend_only() -> None:
    path = ramp_deg(0.0, 60.0)
    plain, _ = drive_knob(make_notchclutch_plant(), 0, path)
    keyed, _ = drive_knob(make_notchclutch_plant(coupling=0.2), 0, path)
    np.testing.assert_array_equal(keyed, plain)  # the other plane straight: nothing to take up
    loops = []
    for coupling in (0.0, 0.2):
        plant = make_notchclutch_plant(coupling=coupling)
        drive_knob(plant, 1, ramp_deg(0.0, 60.0))
        tip, _ = drive_knob(plant, 0, path, other_deg=60.0)
        loops.append(tip)
    assert loops[1][-1] - loops[0][-1] > 2.0  # taken-up slack: the tip bends further


def test_a_unit_is_the_same_every_time_and_differs_from_another() -> None:
    path = np.concatenate([ramp_deg(0.0, 70.0), ramp_deg(70.0, -30.0)])
    a, _ = drive_knob(family_member("notchclutch", 101).build(), 0, path)
    b, _ = drive_knob(family_member("notchclutch", 101).build(), 0, path)
    c, _ = drive_knob(family_member("notchclutch", 102).build(), 0, path)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_notchclutch_is_registered_and_held_out() -> None:
    assert "notchclutch" in PLANT_SPECS
    assert PLANT_ROLE["notchclutch"] == "held-out"
    assert isinstance(family_member("notchclutch", 101).build(), NotchClutchPlant)
    assert set(SCATTER["notchclutch"]) <= set(family_member("notchclutch", 0).params["knobs"][0])
    assert isinstance(load_plant(SPEC), NotchClutchPlant)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"knobs": [{"clutch": 1.0}, {}]}, "unknown notchclutch knob constants: clutch"),
        ({"knobs": [{}]}, "notchclutch takes 2 knobs"),
        ({"knobs": [{"tendon_stiffness_N": 0.0}, {}]}, "tendon_stiffness_N must be > 0"),
        ({"knobs": [{}, {"sheath_friction": -0.1}]}, "sheath_friction must be >= 0"),
        ({"knobs": [{"clutch_kinetic_ratio": 1.2}, {}]}, "clutch_kinetic_ratio must be in"),
        ({"sheath_curvature_deg": math.inf}, "sheath_curvature_deg must be finite"),
        ({"coupling": -0.1}, "coupling must be >= 0"),
    ],
)
def test_bad_constants_are_refused_with_one_clear_line(kwargs: dict[str, object],
                                                       message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        make_notchclutch_plant(**kwargs)  # type: ignore[arg-type]


def test_bad_step_input_and_reshape_are_refused() -> None:
    plant = make_notchclutch_plant()
    with pytest.raises(ValueError, match="knob_deg"):
        plant.step(STEP_S, np.array([math.nan, 0.0]))
    with pytest.raises(PlantLoadError, match="cannot reshape"):
        plant.reshape(stiffness=2.0)
