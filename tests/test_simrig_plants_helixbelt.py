"""The helixbelt plant (blind, session 15): its laws, its behaviours, and its refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from simrig.analysis import measure_dead_zone_backlash
from simrig.family import PLANT_ROLE, PLANT_SPECS, family_member
from simrig.plant import PlantLoadError, load_plant
from simrig.plants.helixbelt import HelixBeltPlant, make_helixbelt_plant
from simrig.plants.helixbelt.laws import helix_wrap_rad, masing_moment_Nmm, mesh_deflection_rad

SPEC = "simrig.plants.helixbelt:make_helixbelt_plant"
EVEN = {"plane_error_deg": 0.0}


def _drive(plant: HelixBeltPlant, knob: int, path_deg: np.ndarray, dt_s: float = 0.004,
           other_deg: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tips (both planes) and the driven knob's torque along ``path_deg``."""
    tips, torques = [], []
    for q in path_deg:
        cmd = np.zeros(2)
        cmd[knob], cmd[1 - knob] = q, other_deg
        s = plant.step(dt_s, cmd)
        tips.append(s.tip_deg.copy())
        torques.append(s.knob_torque_Nm[knob])
    return np.array(tips), np.array(torques), np.asarray(path_deg, dtype=float)


def _sine(cycles: float = 2.0, dt_s: float = 0.004, amp_deg: float = 90.0) -> np.ndarray:
    t = np.arange(0.0, cycles / 0.04, dt_s)
    return amp_deg * np.sin(2.0 * math.pi * 0.04 * t)


def test_a_straight_shaft_gives_the_helix_its_own_wrap() -> None:
    c = 100.0 / (2.0 * math.pi)
    assert helix_wrap_rad(1000.0, 3.0, 100.0, 0.0) == pytest.approx(1000.0 * 3.0 / (9.0 + c * c))


def test_a_curved_shaft_adds_less_wrap_to_a_helix_than_to_a_straight_tendon() -> None:
    own = helix_wrap_rad(1000.0, 3.0, 100.0, 0.0)
    curved = helix_wrap_rad(1000.0, 3.0, 100.0, math.pi / 2.0)
    assert own < curved < own + math.pi / 2.0


def test_the_belt_floats_in_its_clearance_then_stiffens_with_load() -> None:
    assert mesh_deflection_rad(0.0, 0.02, 0.05, 200.0) == 0.0
    d1 = mesh_deflection_rad(50.0, 0.02, 0.05, 200.0) - 0.02
    d2 = mesh_deflection_rad(200.0, 0.02, 0.05, 200.0) - 0.02
    assert d2 == pytest.approx(2.0 * d1)  # four times the torque, twice the deflection
    assert mesh_deflection_rad(-200.0, 0.02, 0.05, 200.0) == pytest.approx(-0.07)


def test_a_masing_branch_closes_on_the_reversal_it_left() -> None:
    up = masing_moment_Nmm(0.3, -0.3, -1.0, 1.0, 0.05)
    down = masing_moment_Nmm(-0.3, 0.3, up, 1.0, 0.05)
    assert up == pytest.approx(1.0, abs=1e-4)
    assert down == pytest.approx(-1.0, abs=1e-4)
    assert masing_moment_Nmm(0.3, 0.3, 0.4, 1.0, 0.05) == 0.4


def test_two_plants_driven_alike_answer_alike() -> None:
    a, b = make_helixbelt_plant(), make_helixbelt_plant()
    for q in np.linspace(0.0, 80.0, 150):
        sa, sb = a.step(0.002, np.array([q, -0.5 * q])), b.step(0.002, np.array([q, -0.5 * q]))
    assert np.array_equal(sa.tip_deg, sb.tip_deg)
    assert np.array_equal(sa.knob_torque_Nm, sb.knob_torque_Nm)


def test_reset_straightens_and_unloads_the_catheter() -> None:
    plant = make_helixbelt_plant()
    _drive(plant, 0, np.linspace(0.0, 80.0, 200))
    plant.reset()
    s = plant.step(0.004, np.zeros(2))
    assert np.array_equal(s.tip_deg, np.zeros(2))
    assert np.array_equal(s.knob_torque_Nm, np.zeros(2))


def test_the_tip_does_not_depend_on_the_time_step() -> None:
    a, b = make_helixbelt_plant(), make_helixbelt_plant()
    ta, _, _ = _drive(a, 0, np.linspace(0.0, 80.0, 1601), dt_s=0.0005)
    tb, _, _ = _drive(b, 0, np.linspace(0.0, 80.0, 201), dt_s=0.004)
    assert abs(ta[-1, 0] - tb[-1, 0]) < 0.05


def test_the_slack_leaves_the_tip_straight_and_the_knob_unloaded() -> None:
    plant = make_helixbelt_plant()
    tips, torque, _ = _drive(plant, 0, np.linspace(0.0, 10.0, 400))
    assert np.max(np.abs(tips)) < 1e-9
    assert np.max(np.abs(torque)) <= plant.knobs[0].handle_friction_Nm + 1e-12


def test_symmetric_knobs_bend_alike_both_ways() -> None:
    up, down = make_helixbelt_plant(knobs=[EVEN, EVEN]), make_helixbelt_plant(knobs=[EVEN, EVEN])
    tu, qu, _ = _drive(up, 0, np.linspace(0.0, 80.0, 400))
    td, qd, _ = _drive(down, 0, np.linspace(0.0, -80.0, 400))
    assert tu[-1, 0] == pytest.approx(-td[-1, 0], abs=1e-9)
    assert qu[-1] == pytest.approx(-qd[-1], abs=1e-12)


def test_a_sweep_has_a_dead_zone_and_a_backlash_of_a_tee_probe() -> None:
    q = _sine()
    tips, _, _ = _drive(make_helixbelt_plant(), 0, q)
    m = measure_dead_zone_backlash(q, tips[:, 0])
    assert 10.0 <= m.dead_zone_pos_deg <= 25.0 and -25.0 <= m.dead_zone_neg_deg <= -10.0
    assert 5.0 <= m.backlash_pos_deg <= 20.0 and 5.0 <= m.backlash_neg_deg <= 20.0


def test_a_closed_knob_cycle_takes_work_from_the_motor() -> None:
    q = _sine()
    _, torque, _ = _drive(make_helixbelt_plant(knobs=[{"handle_friction_Nm": 0.0}] * 2), 0, q)
    half = q.size // 2  # the second cycle: a closed loop from the same state
    work_J = float(np.sum(0.5 * (torque[half + 1:] + torque[half:-1])
                          * np.radians(np.diff(q[half:]))))
    assert work_J > 0.0


def test_the_tendon_load_reaches_the_knob_and_drops_when_released() -> None:
    plant = make_helixbelt_plant()
    _, loaded, _ = _drive(plant, 0, np.linspace(0.0, 90.0, 900))
    _, released, _ = _drive(plant, 0, np.linspace(90.0, 60.0, 300))
    assert loaded[-1] > 0.1
    assert released[-1] < 0.2 * loaded[-1]


def test_the_helix_phase_error_bends_the_other_plane() -> None:
    tips, _, _ = _drive(make_helixbelt_plant(), 0, np.linspace(0.0, 80.0, 400))
    error = make_helixbelt_plant().knobs[0].plane_error_deg
    assert tips[-1, 1] == pytest.approx(tips[-1, 0] * math.tan(math.radians(error)), rel=1e-9)


def test_more_slack_widens_the_dead_zone() -> None:
    plain, slack = make_helixbelt_plant(), make_helixbelt_plant()
    slack.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    path = np.linspace(0.0, 60.0, 600)
    tp, _, _ = _drive(plain, 0, path)
    ts, _, _ = _drive(slack, 0, path)
    assert tp[-1, 0] - ts[-1, 0] > 1.0


def test_a_curved_shaft_keeps_the_dead_zone_and_adds_a_little_backlash() -> None:
    """The helix keeps the tendons' length (no slack change) and a 120 deg curve adds far less
    than 120 deg of wrap to the helix's own 11 rad."""
    q = _sine()
    straight, _, _ = _drive(make_helixbelt_plant(), 0, q)
    curved, _, _ = _drive(make_helixbelt_plant(sheath_curvature_deg=120.0), 0, q)
    ms = measure_dead_zone_backlash(q, straight[:, 0])
    mc = measure_dead_zone_backlash(q, curved[:, 0])
    assert mc.dead_zone_pos_deg == pytest.approx(ms.dead_zone_pos_deg, abs=1e-6)
    assert ms.backlash_pos_deg < mc.backlash_pos_deg < ms.backlash_pos_deg + 2.0


def test_the_plant_loads_from_its_spec_and_from_the_family() -> None:
    assert isinstance(load_plant(SPEC), HelixBeltPlant)
    assert isinstance(family_member("helixbelt", 101).build(), HelixBeltPlant)


def test_helixbelt_keeps_its_place_in_the_family_and_is_held_out() -> None:
    assert list(PLANT_SPECS).index("helixbelt") == 8  # its units keep their draws
    assert PLANT_ROLE["helixbelt"] == "held-out"


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"knobs": [{"tendon_stiffness_N": -1.0}, {}]}, "tendon_stiffness_N must be > 0"),
        ({"knobs": [{"spring": 1.0}, {}]}, "unknown helixbelt knob constants: spring"),
        ({"knobs": [{}]}, "knobs must list 2 knobs"),
        ({"knobs": [{"braid_slip_deg": 0.0}, {}]}, "braid_slip_deg must be > 0"),
        ({"sheath_curvature_deg": -5.0}, "sheath_curvature_deg must be finite and >= 0"),
    ],
)
def test_bad_constants_are_refused(params: dict[str, object], message: str) -> None:
    with pytest.raises((ValueError, PlantLoadError), match=message):
        load_plant(SPEC, params)


def test_bad_steps_and_shapes_are_refused() -> None:
    plant = make_helixbelt_plant()
    with pytest.raises(ValueError, match="knob_deg must be 2 finite angles"):
        plant.step(0.004, np.array([math.nan, 0.0]))
    with pytest.raises(ValueError, match="slack must stay >= 0"):
        plant.reshape(slack_delta_mm=((-5.0, 0.0), (0.0, 0.0)))
