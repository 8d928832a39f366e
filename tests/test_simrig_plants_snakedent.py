"""The snakedent plant (blind, session 22): laws, energy and geometry, registration, refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.plant_drive import drive_knob, ramp_deg

from simrig.analysis import measure_dead_zone_backlash
from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import PlantLoadError, load_plant
from simrig.plants.snakedent import SnakeDentPlant, make_snakedent_plant
from simrig.plants.snakedent.laws import (
    detent_torque_Nm,
    lumen_contact,
    rope_arm_mm,
    rope_lengthening_mm,
)
from simrig.report import run_sweep

SPEC = "simrig.plants.snakedent:make_snakedent_plant"


def _cycle(top_deg: float) -> np.ndarray:
    return np.concatenate([ramp_deg(0.0, top_deg), ramp_deg(top_deg, -top_deg),
                           ramp_deg(-top_deg, 0.0)])


def test_a_rolling_joint_shortens_the_pulling_rope_and_tightens_the_pair() -> None:
    theta = math.radians(15.0)
    pulling, paying = (rope_lengthening_mm(theta, s * 2.2, 0.7) for s in (1.0, -1.0))
    assert pulling < 0.0 < paying
    assert pulling + paying > 0.0


def test_a_rope_of_the_other_plane_is_taken_up_by_this_planes_bend() -> None:
    assert rope_lengthening_mm(0.0, 0.0, 0.7) == 0.0
    assert rope_lengthening_mm(math.radians(15.0), 0.0, 0.7) > 0.0
    assert rope_lengthening_mm(math.radians(-15.0), 0.0, 0.7) > 0.0


def test_the_moment_arm_falls_as_the_joint_bends() -> None:
    assert rope_arm_mm(0.0, 2.2, 0.7) == pytest.approx(2.2)
    assert rope_arm_mm(math.radians(20.0), 2.2, 0.7) < rope_arm_mm(math.radians(10.0), 2.2, 0.7)


def test_a_held_contact_keeps_its_place_and_a_drawn_one_slides_to_its_capacity() -> None:
    held = lumen_contact(1.0, 0.0, 0.5, 80.0, 2.0, 0.5)
    assert held[0] == 0.5
    z, proximal, distal, _ = lumen_contact(2.0, 0.0, 0.5, 80.0, 2.0, 0.5)
    assert z > 0.5 and proximal == pytest.approx(2.0 * distal + 0.5)


def test_a_paid_out_contact_slides_back_with_the_distal_rope_the_tighter() -> None:
    z, proximal, distal, _ = lumen_contact(0.0, -0.5, 0.5, 80.0, 2.0, 0.5)
    assert z < 0.5 and distal == pytest.approx(2.0 * proximal + 0.5)


def test_the_detent_does_no_net_work_over_a_notch() -> None:
    q = np.linspace(0.0, 15.0, 1501)
    work = np.trapezoid([detent_torque_Nm(x, 0.003, 15.0) for x in q], q)
    assert abs(work) < 1e-9


def test_dead_zone_and_backlash_are_those_of_a_probe() -> None:
    """Dead zone up to 28 deg: the paper's uncompensated PTPE (58-69 deg) needs 23-26 here."""
    for knob in (0, 1):
        rec = run_sweep(make_snakedent_plant(), knob)
        m = measure_dead_zone_backlash(rec.knob_deg, rec.tip_deg)
        assert 10.0 <= m.dead_zone_pos_deg <= 28.0 and 10.0 <= -m.dead_zone_neg_deg <= 28.0
        assert 5.0 <= m.backlash_pos_deg <= 20.0 and 5.0 <= m.backlash_neg_deg <= 20.0


def test_the_tip_follows_the_knob_and_is_straight_at_rest() -> None:
    plant = make_snakedent_plant()
    assert np.all(plant.step(0.004, np.zeros(2)).tip_deg == 0.0)
    tip, _ = drive_knob(plant, 0, ramp_deg(0.0, 60.0))
    assert tip[-1] > 40.0
    tip, _ = drive_knob(plant, 1, ramp_deg(0.0, -60.0))
    assert tip[-1] < -40.0


def test_a_closed_knob_cycle_takes_work_from_the_motor() -> None:
    plant = make_snakedent_plant()
    path = _cycle(90.0)
    _, torque = drive_knob(plant, 0, path)
    assert float(np.sum(torque[1:] * np.diff(path))) > 0.0


def test_the_other_plane_bent_narrows_this_planes_dead_zone() -> None:
    def threshold(other_deg: float) -> float:
        plant = make_snakedent_plant()
        drive_knob(plant, 1, ramp_deg(0.0, other_deg))
        tip, _ = drive_knob(plant, 0, ramp_deg(0.0, 40.0), other_deg)
        return float(ramp_deg(0.0, 40.0)[np.argmax(tip > 1.0)])

    assert threshold(80.0) < threshold(0.0) - 0.5


def test_the_coupling_keyword_takes_up_this_plane_more_with_the_other_bent() -> None:
    def tip_at_30(coupling: float) -> float:
        plant = make_snakedent_plant(coupling=coupling)
        drive_knob(plant, 1, ramp_deg(0.0, 80.0))
        return float(drive_knob(plant, 0, ramp_deg(0.0, 30.0), 80.0)[0][-1])

    def tip_straight(coupling: float) -> float:
        plant = make_snakedent_plant(coupling=coupling)
        return float(drive_knob(plant, 0, ramp_deg(0.0, 30.0))[0][-1])

    assert tip_at_30(4.5) > tip_at_30(0.0) + 0.5
    # the other knob at 0: its plane stays all but straight, so next to no change
    assert tip_straight(4.5) == pytest.approx(tip_straight(0.0), abs=0.05)


def test_the_backlash_grows_with_the_load_at_the_reversal() -> None:
    def travel_back(top_deg: float) -> float:
        plant = make_snakedent_plant()
        tip, _ = drive_knob(plant, 0, ramp_deg(0.0, top_deg))
        back = ramp_deg(top_deg, top_deg - 30.0)
        tip_back, _ = drive_knob(plant, 0, back)
        return float(top_deg - back[np.argmax(tip_back < tip[-1] - 1.0)])

    assert travel_back(90.0) > travel_back(50.0) + 0.5


def test_slack_grown_by_a_reshape_delays_the_tip() -> None:
    def tip_at_30(plant: SnakeDentPlant) -> float:
        return float(drive_knob(plant, 0, ramp_deg(0.0, 30.0))[0][-1])

    grown = make_snakedent_plant()
    grown.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    assert tip_at_30(grown) < tip_at_30(make_snakedent_plant()) - 3.0
    with pytest.raises(ValueError, match="cannot reshape 'rope'"):
        grown.reshape(rope=1.0)


def test_a_curved_sheath_takes_more_torque_for_the_same_bend() -> None:
    straight, curved = make_snakedent_plant(), make_snakedent_plant()
    curved.reshape(sheath_curvature_deg=120.0)
    path = ramp_deg(0.0, 70.0)
    assert drive_knob(curved, 0, path)[1][-1] > drive_knob(straight, 0, path)[1][-1]


def test_a_unit_is_the_same_catheter_for_the_same_seed() -> None:
    a, b = family_member("snakedent", 102).build(), family_member("snakedent", 102).build()
    c = family_member("snakedent", 102, seed=1).build()
    path = _cycle(70.0)
    tip_a, tq_a = drive_knob(a, 0, path)
    tip_b, tq_b = drive_knob(b, 0, path)
    assert np.array_equal(tip_a, tip_b) and np.array_equal(tq_a, tq_b)
    assert not np.array_equal(tip_a, drive_knob(c, 0, path)[0])


def test_snakedent_is_registered_after_cyclopebax_and_held_out() -> None:
    names = list(PLANT_SPECS)
    assert names.index("snakedent") == names.index("cyclopebax") + 1
    assert PLANT_ROLE["snakedent"] == "held-out"
    assert isinstance(family_member("snakedent", 101).build(), SnakeDentPlant)
    assert set(SCATTER["snakedent"]) <= set(family_member("snakedent", 0).params["knobs"][0])
    assert isinstance(load_plant(SPEC), SnakeDentPlant)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"knobs": [{"vertebra": 1.0}, {}]}, "unknown snakedent knob constants: vertebra"),
        ({"knobs": [{}]}, "snakedent takes 2 knobs"),
        ({"knobs": [{"tendon_stiffness_N": 0.0}, {}]}, "tendon_stiffness_N must be > 0"),
        ({"knobs": [{}, {"sheath_friction": -0.1}]}, "sheath_friction must be >= 0"),
        ({"knobs": [{"hole_depth_mm": 4.0}, {}]}, "hole_depth_mm must be <= roll_radius_mm"),
        ({"knobs": [{"tendon_offset_mm": 3.5}, {}]}, "tendon_offset_mm must be < roll_radius"),
        ({"sheath_curvature_deg": -10.0}, "sheath_curvature_deg must be >= 0"),
        ({"coupling": -1.0}, "coupling must be >= 0"),
    ],
)
def test_bad_constants_are_refused_with_one_clear_line(kwargs: dict[str, object],
                                                       message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        make_snakedent_plant(**kwargs)  # type: ignore[arg-type]


def test_bad_step_input_is_refused() -> None:
    with pytest.raises(ValueError, match="dt_s must be >= 0"):
        make_snakedent_plant().step(-0.001, np.zeros(2))
    with pytest.raises(ValueError, match="knob_deg must be 2 finite angles"):
        make_snakedent_plant().step(0.004, np.array([math.nan, 0.0]))
