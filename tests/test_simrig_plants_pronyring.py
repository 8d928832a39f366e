"""The eighteenth plant, pronyring (written blind in session 25): a Pebax section with a Prony
relaxation spectrum, a pull ring on a compliant bond (tilt, set-back, seat friction), stainless
ropes in PTFE liners whose friction falls with load, along a path whose lower bend breathes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.plant_drive import STEP_S, drive_knob, ramp_deg

from simrig.analysis import measure_dead_zone_backlash
from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import PlantLoadError, load_plant
from simrig.plants.pronyring import PronyRingPlant, make_pronyring_plant
from simrig.plants.pronyring.laws import liner_friction, prony_moment, relax, rope_contact

SPEC = "simrig.plants.pronyring:make_pronyring_plant"


def _cycles(plant: PronyRingPlant, amp_deg: float = 90.0, other_deg: float = 0.0,
            knob: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Two full +-amp cycles of one knob at 20 deg/s: knob path, tip, torque."""
    path = np.concatenate([ramp_deg(0.0, amp_deg), ramp_deg(amp_deg, -amp_deg),
                           ramp_deg(-amp_deg, amp_deg), ramp_deg(amp_deg, -amp_deg),
                           ramp_deg(-amp_deg, 0.0)])
    tip, torque = drive_knob(plant, knob, path, other_deg)
    return path, tip, torque


def test_a_dead_zone_of_the_paper_s_size_from_the_ropes_slack() -> None:
    q, tip, _ = _cycles(make_pronyring_plant())
    m = measure_dead_zone_backlash(q, tip)
    assert 15.0 < m.dead_zone_pos_deg < 35.0
    assert -35.0 < m.dead_zone_neg_deg < -15.0


def test_inside_the_slack_the_tip_stays_straight_and_the_knob_feels_only_its_seal() -> None:
    plant = make_pronyring_plant()
    tip, torque = drive_knob(plant, 0, ramp_deg(0.0, 20.0))
    assert np.max(np.abs(tip)) < 0.5
    assert np.allclose(torque[5:], 0.05, atol=0.005)


def test_backlash_grows_with_the_load_the_ropes_carry() -> None:
    small = measure_dead_zone_backlash(*_cycles(make_pronyring_plant(), 60.0)[:2])
    large = measure_dead_zone_backlash(*_cycles(make_pronyring_plant(), 90.0)[:2])
    assert large.backlash_pos_deg > small.backlash_pos_deg + 3.0


def test_the_torque_falls_at_a_reversal_while_the_tip_holds() -> None:
    q, tip, torque = _cycles(make_pronyring_plant())
    top = int(np.argmax(q[: len(q) // 2]))
    after = top + int(5.0 / (20.0 * STEP_S))  # 5 knob deg after the reversal
    assert torque[after] < 0.6 * torque[top]
    assert abs(tip[after] - tip[top]) < 0.5


def test_a_held_knob_lets_the_section_creep_and_the_rope_relax() -> None:
    plant = make_pronyring_plant()
    drive_knob(plant, 0, ramp_deg(0.0, 70.0))
    tip, torque = drive_knob(plant, 0, np.full(int(60.0 / STEP_S), 70.0))
    assert tip[-1] > tip[250] + 2.0
    assert torque[-1] < torque[250]


def test_a_released_section_recovers_its_creep_over_minutes() -> None:
    plant = make_pronyring_plant()
    drive_knob(plant, 0, ramp_deg(0.0, 70.0))
    drive_knob(plant, 0, np.full(int(60.0 / STEP_S), 70.0))
    drive_knob(plant, 0, ramp_deg(70.0, 0.0))
    tip, _ = drive_knob(plant, 0, np.zeros(int(120.0 / STEP_S)))
    assert tip[0] > 3.0
    assert tip[int(30.0 / STEP_S)] < tip[0] - 2.0
    assert 0.0 < tip[-1] < tip[int(30.0 / STEP_S)]


def test_the_other_plane_s_load_moves_this_plane_s_dead_zone_and_backlash() -> None:
    free = measure_dead_zone_backlash(*_cycles(make_pronyring_plant(), 90.0, 0.0)[:2])
    loaded = measure_dead_zone_backlash(*_cycles(make_pronyring_plant(), 90.0, 80.0)[:2])
    assert abs(loaded.dead_zone_pos_deg - free.dead_zone_pos_deg) > 1.0
    assert loaded.backlash_pos_deg > free.backlash_pos_deg + 2.0


def test_the_clocked_anchors_tilt_the_other_plane_s_tip() -> None:
    still = {"breathing_wrap_deg": 0.0}
    plant = make_pronyring_plant(knobs=[still, still])
    drive_knob(plant, 1, ramp_deg(0.0, 80.0))
    tip = plant.step(STEP_S, np.array([0.0, 80.0])).tip_deg
    assert tip[1] > 40.0
    assert 0.2 < abs(tip[0]) < 3.0
    unclocked = make_pronyring_plant(knobs=[{**still, "ring_clocking_deg": 0.0}] * 2)
    drive_knob(unclocked, 1, ramp_deg(0.0, 80.0))
    assert abs(unclocked.step(STEP_S, np.array([0.0, 80.0])).tip_deg[0]) < 0.05


def test_breathing_moves_a_held_anterior_posterior_tip_not_the_right_left_one() -> None:
    ap = make_pronyring_plant()
    drive_knob(ap, 0, ramp_deg(0.0, 60.0))
    tip_ap, _ = drive_knob(ap, 0, np.full(int(8.0 / STEP_S), 60.0))
    rl = make_pronyring_plant()
    drive_knob(rl, 1, ramp_deg(0.0, 60.0))
    tip_rl, _ = drive_knob(rl, 1, np.full(int(8.0 / STEP_S), 60.0))
    t = np.arange(tip_ap.size) * STEP_S
    late = t > 2.0  # the section's creep is smooth over seconds: a quadratic takes it out

    def breathing_deg(tip: np.ndarray) -> float:
        trend = np.polyval(np.polyfit(t[late], tip[late], 2), t[late])
        return float(np.ptp(tip[late] - trend))

    assert breathing_deg(tip_ap) > 0.3
    assert breathing_deg(tip_rl) < 0.05


def test_ptfe_friction_falls_with_the_rope_s_load() -> None:
    assert liner_friction(0.3, 40.0, 10.0, 0.15) < liner_friction(0.3, 10.0, 10.0, 0.15) == 0.3
    assert liner_friction(0.3, 0.0, 10.0, 0.15) == liner_friction(0.3, 1.0, 10.0, 0.15)


def test_a_rope_sticks_inside_its_capstan_band_and_slides_at_its_edge() -> None:
    stuck = rope_contact(1.0, 0.0, 0.5, 40.0, 10.0, 5.0, 0.0)  # 20 N against 5 N: inside 1/5..5
    assert stuck.centroid_mm == 0.5 and stuck.proximal_N == 20.0 and stuck.distal_N == 5.0
    pulled = rope_contact(2.0, 0.0, 0.5, 40.0, 10.0, 2.0, 0.0)
    assert pulled.proximal_N == pytest.approx(2.0 * pulled.distal_N)
    released = rope_contact(0.2, 0.0, 0.5, 40.0, 10.0, 2.0, 0.0)
    assert released.distal_N == pytest.approx(2.0 * released.proximal_N)


def test_the_section_is_stiffer_fast_than_slow_and_its_branches_relax() -> None:
    branches = ((10.0, 3.0, 0.0),)
    fast, k_fast = prony_moment(1.0, branches, 60.0, 0.004)
    assert fast > 69.0 and k_fast > 69.0
    rest = 0.0
    for _ in range(int(30.0 / 0.004)):
        rest = relax(rest, 1.0, 3.0, 0.004)
    assert prony_moment(1.0, ((10.0, 3.0, rest),), 60.0, 0.004)[0] == pytest.approx(60.0, abs=0.01)


def test_added_slack_and_a_curved_shaft_reshape_the_dead_zone() -> None:
    base = measure_dead_zone_backlash(*_cycles(make_pronyring_plant())[:2])
    slack = make_pronyring_plant()
    slack.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    wider = measure_dead_zone_backlash(*_cycles(slack)[:2])
    assert wider.dead_zone_pos_deg > base.dead_zone_pos_deg + 2.0
    curved = measure_dead_zone_backlash(
        *_cycles(make_pronyring_plant(sheath_curvature_deg=60.0))[:2])
    assert curved.dead_zone_pos_deg != pytest.approx(base.dead_zone_pos_deg, abs=0.5)


def test_a_unit_is_the_same_catheter_every_time_and_units_differ() -> None:
    runs = [_cycles(family_member("pronyring", u).build())[1] for u in (3, 3, 4)]
    assert np.array_equal(runs[0], runs[1])
    assert np.max(np.abs(runs[0] - runs[2])) > 1.0


def test_reset_returns_to_straight_and_unloaded() -> None:
    plant = make_pronyring_plant()
    first = _cycles(plant)[1]
    plant.reset()
    assert np.array_equal(_cycles(plant)[1], first)


def test_pronyring_is_registered_and_held_out() -> None:
    assert "pronyring" in PLANT_SPECS
    assert PLANT_ROLE["pronyring"] == "held-out"
    assert isinstance(family_member("pronyring", 101).build(), PronyRingPlant)
    assert set(SCATTER["pronyring"]) <= set(family_member("pronyring", 0).params["knobs"][0])
    assert isinstance(load_plant(SPEC), PronyRingPlant)


def test_the_coupling_keyword_takes_up_the_ropes_by_the_other_planes_bend() -> None:
    path = ramp_deg(0.0, 80.0)
    plain, _ = drive_knob(make_pronyring_plant(), 0, path)
    keyed, _ = drive_knob(make_pronyring_plant(coupling=0.6), 0, path)
    # the other knob at 0: its ropes, taken up by this plane's bend, only load the ring's seat
    np.testing.assert_allclose(keyed, plain, atol=0.3)
    loops = []
    for coupling in (0.0, 0.6):
        plant = make_pronyring_plant(coupling=coupling)
        drive_knob(plant, 1, ramp_deg(0.0, 80.0))
        tip, _ = drive_knob(plant, 0, path, other_deg=80.0)
        loops.append(tip)
    assert loops[1][-1] - loops[0][-1] > 2.0  # taken-up slack: the tip bends further


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"knobs": [{"ring": 1.0}, {}]}, "unknown pronyring knob constants: ring"),
        ({"knobs": [{}]}, "pronyring takes 2 knobs"),
        ({"knobs": [{"tendon_stiffness_N": 0.0}, {}]}, "tendon_stiffness_N must be > 0"),
        ({"knobs": [{}, {"sheath_friction": -0.1}]}, "sheath_friction must be >= 0"),
        ({"knobs": [{"contact_fraction": 1.0}, {}]}, "contact_fraction must be in"),
        ({"knobs": [{"prony_mid_s": math.nan}, {}]}, "prony_mid_s must be finite"),
        ({"sheath_curvature_deg": math.inf}, "sheath_curvature_deg must be finite"),
        ({"coupling": -0.1}, "coupling must be >= 0"),
        ({"coupling": math.nan}, "coupling must be finite"),
    ],
)
def test_bad_constants_are_refused_with_one_clear_line(kwargs: dict[str, object],
                                                       message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        make_pronyring_plant(**kwargs)  # type: ignore[arg-type]


def test_bad_step_input_and_reshape_are_refused() -> None:
    plant = make_pronyring_plant()
    with pytest.raises(ValueError, match="knob_deg"):
        plant.step(STEP_S, np.array([math.nan, 0.0]))
    with pytest.raises(PlantLoadError, match="cannot reshape"):
        plant.reshape(stiffness=2.0)
