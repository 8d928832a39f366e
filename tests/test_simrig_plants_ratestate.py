"""The ratestate plant (blind in session 16, held out since 17): laws, behaviours, refusals."""

from __future__ import annotations

import numpy as np
import pytest
from support.plant_drive import STEP_S, drive_knob, ramp_deg

from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import Plant, PlantLoadError, load_plant
from simrig.plants.ratestate import NODES, RateStatePlant, make_ratestate_plant
from simrig.plants.ratestate.laws import age_after, aged_friction, wrap_profile_rad

SPEC = "simrig.plants.ratestate:make_ratestate_plant"
DT = STEP_S



def test_a_stuck_contact_ages_by_the_time_it_stuck() -> None:
    age = age_after(np.array([0.5]), np.array([0.0]), 0.25, np.array([0.02]))
    assert age[0] == pytest.approx(0.75)


def test_a_sliding_contact_ages_towards_its_slip_distance_over_speed() -> None:
    age = np.array([100.0])
    for _ in range(200):  # 1 mm/s for 0.8 s: 40 slip distances
        age = age_after(age, np.array([0.004]), DT, np.array([0.02]))
    assert age[0] == pytest.approx(0.02 / 1.0, rel=1e-3)


def test_friction_grows_with_the_age_of_a_contact() -> None:
    mu = aged_friction(np.full(3, 0.15), np.full(3, 0.006), np.array([0.01, 1.0, 100.0]),
                       np.full(3, 0.01))
    assert mu[0] < mu[1] < mu[2]
    assert mu[2] - mu[1] == pytest.approx(0.006 * np.log(10001.0 / 101.0))


def test_the_wrap_profile_carries_the_whole_wrap_and_the_extra_curve() -> None:
    wrap = wrap_profile_rad(260.0, NODES, 0.6, 0.45, extra_curve_deg=120.0)
    assert wrap.sum() == pytest.approx(np.radians(380.0))
    assert np.argmax(wrap) in (NODES // 2 - 1, NODES // 2, NODES // 2 + 1)


def test_the_plant_follows_the_protocol_and_loads_by_name() -> None:
    plant = load_plant(SPEC)
    assert isinstance(plant, Plant) and isinstance(plant, RateStatePlant)


def test_same_inputs_give_the_same_outputs() -> None:
    path = np.concatenate([ramp_deg(0.0, 70.0), ramp_deg(70.0, -40.0)])
    a, b = make_ratestate_plant(), make_ratestate_plant()
    assert np.array_equal(drive_knob(a, 0, path)[0], drive_knob(b, 0, path)[0])


def test_reset_returns_to_the_straight_unloaded_state() -> None:
    plant = make_ratestate_plant()
    fresh = drive_knob(make_ratestate_plant(), 0, ramp_deg(0.0, 60.0))
    drive_knob(plant, 0, ramp_deg(0.0, 80.0))
    plant.reset()
    again = drive_knob(plant, 0, ramp_deg(0.0, 60.0))
    assert np.allclose(fresh[0], again[0]) and np.allclose(fresh[1], again[1])


def test_inside_the_slack_the_tip_stays_straight_and_only_the_knob_bearing_loads() -> None:
    plant = make_ratestate_plant()
    tips, torques = drive_knob(plant, 0, ramp_deg(0.0, 10.0))
    assert np.max(np.abs(tips)) < 1e-6
    assert np.max(np.abs(plant.tensions_N())) < 1e-6
    assert torques[-1] == pytest.approx(plant.knobs[0].handle_friction_Nm, rel=0.01)


def test_pulling_further_bends_the_tip_further() -> None:
    tips, _ = drive_knob(make_ratestate_plant(), 0, ramp_deg(0.0, 90.0))
    loaded = tips[tips > 1.0]
    assert loaded.size > 100 and np.all(np.diff(loaded) > -1e-9)
    assert 60.0 < tips[-1] < 110.0


def test_while_pulling_the_tension_falls_from_the_drum_to_the_tip() -> None:
    plant = make_ratestate_plant()
    drive_knob(plant, 0, ramp_deg(0.0, 80.0))
    pos = plant.tensions_N()[0, :NODES + 1]
    assert np.all(np.diff(pos) < 0.0)
    assert pos[0] / pos[-1] > 1.5  # friction along the whole shaft (capstan-like)


def test_a_reversal_unloads_the_tendon_from_the_drum_inwards() -> None:
    plant = make_ratestate_plant()
    drive_knob(plant, 0, ramp_deg(0.0, 80.0))
    loaded = plant.tensions_N()[0, :NODES + 1].copy()
    drive_knob(plant, 0, ramp_deg(80.0, 78.0))
    drop = loaded - plant.tensions_N()[0, :NODES + 1]
    assert drop[0] > 1.0 and drop[-1] < 0.25 * drop[0]  # the tip end still holds its load
    assert np.all(np.diff(drop) <= 1e-9)


def test_the_tip_holds_after_a_reversal_then_returns() -> None:
    plant = make_ratestate_plant()
    drive_knob(plant, 0, ramp_deg(0.0, 90.0))
    tips, _ = drive_knob(plant, 0, ramp_deg(90.0, 0.0))
    moved = np.argmax(tips < tips[0] - 1.0)
    held_deg = 90.0 * moved / tips.size
    assert 4.0 < held_deg < 25.0
    assert tips[-1] < 0.5 * tips[0]


def test_a_closed_knob_cycle_dissipates_energy() -> None:
    plant = make_ratestate_plant(knobs=[{"handle_friction_Nm": 0.0}] * 2)
    path = np.concatenate([ramp_deg(0.0, 90.0), ramp_deg(90.0, -90.0), ramp_deg(-90.0, 0.0)])
    _, torques = drive_knob(plant, 0, path)
    work_J = float(np.sum(0.5 * (torques[1:] + torques[:-1]) * np.radians(np.diff(path))))
    assert work_J > 0.0


def test_static_friction_grows_with_the_time_the_tendon_stood_still() -> None:
    def resume_torque(dwell_s: float) -> float:
        plant = make_ratestate_plant()
        drive_knob(plant, 0, ramp_deg(0.0, 60.0))
        drive_knob(plant, 0, np.full(int(dwell_s / DT) + 1, 60.0))
        _, torques = drive_knob(plant, 0, ramp_deg(60.0, 64.0))
        return float(np.max(torques))

    assert resume_torque(60.0) > resume_torque(0.0) + 1e-3


def test_bending_the_other_plane_adds_friction_to_this_one() -> None:
    path = ramp_deg(0.0, 80.0)
    _, straight = drive_knob(make_ratestate_plant(), 0, path)
    bent = make_ratestate_plant()
    drive_knob(bent, 1, ramp_deg(0.0, 80.0))
    _, coupled = drive_knob(bent, 0, path, other_deg=80.0)
    assert coupled[-1] > straight[-1] * 1.01


def test_a_curved_shaft_needs_more_torque_and_bends_the_tip_less() -> None:
    path = ramp_deg(0.0, 90.0)
    tip_s, tau_s = drive_knob(make_ratestate_plant(), 0, path)
    tip_c, tau_c = drive_knob(make_ratestate_plant(sheath_curvature_deg=120.0), 0, path)
    assert tau_c[-1] > tau_s[-1] and tip_c[-1] < tip_s[-1]


def test_ratestate_is_registered_after_helixbelt_and_held_out() -> None:
    names = list(PLANT_SPECS)
    assert names.index("ratestate") == names.index("helixbelt") + 1
    assert PLANT_ROLE["ratestate"] == "held-out"
    assert isinstance(family_member("ratestate", 101).build(), RateStatePlant)
    assert set(SCATTER["ratestate"]) <= set(family_member("ratestate", 0).params["knobs"][0])


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"knobs": [{"spring": 1.0}, {}]}, "unknown ratestate knob constants: spring"),
        ({"knobs": [{}]}, "ratestate takes 2 knobs"),
        ({"knobs": [{"tendon_stiffness_N": 0.0}, {}]}, "tendon_stiffness_N must be > 0"),
        ({"knobs": [{}, {"sheath_friction": -0.1}]}, "sheath_friction must be >= 0"),
        ({"knobs": [{"curve_share": 1.5}, {}]}, "curve_position and curve_share"),
        ({"sheath_curvature_deg": -10.0}, "sheath_curvature_deg must be >= 0"),
    ],
)
def test_bad_constants_are_refused_with_one_clear_line(kwargs: dict[str, object],
                                                       message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        make_ratestate_plant(**kwargs)  # type: ignore[arg-type]


def test_bad_step_input_is_refused() -> None:
    with pytest.raises(ValueError, match="dt_s must be >= 0"):
        make_ratestate_plant().step(-0.001, np.zeros(2))
    with pytest.raises(ValueError, match="knob_deg must be 2 finite angles"):
        make_ratestate_plant().step(DT, np.array([np.nan, 0.0]))


def test_more_slack_mid_run_widens_the_dead_zone() -> None:
    path = ramp_deg(0.0, 45.0)
    plain, slackened = make_ratestate_plant(), make_ratestate_plant()
    slackened.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    tip_plain, _ = drive_knob(plain, 0, path)
    tip_slack, _ = drive_knob(slackened, 0, path)
    assert tip_slack[-1] < tip_plain[-1] - 2.0


def test_bending_the_shaft_mid_run_adds_friction() -> None:
    plant = make_ratestate_plant()
    plant.reshape(sheath_curvature_deg=120.0)
    assert plant.sheath_curvature_deg == 120.0
    _, bent = drive_knob(plant, 0, ramp_deg(0.0, 80.0))
    _, straight = drive_knob(make_ratestate_plant(), 0, ramp_deg(0.0, 80.0))
    assert bent[-1] > straight[-1]


def test_unknown_reshapes_are_refused() -> None:
    with pytest.raises(PlantLoadError, match="cannot reshape stiffness"):
        make_ratestate_plant().reshape(stiffness=2.0)
