"""The cyclopebax plant (blind, session 21): laws, energy and geometry, registration, refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.plant_drive import drive_knob, ramp_deg

from simrig.analysis import measure_dead_zone_backlash
from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import PlantLoadError, load_plant
from simrig.plants.cyclopebax import CycloPebaxPlant, make_cyclopebax_plant
from simrig.plants.cyclopebax.laws import grips, lumen_contact, mesh_twist_deg, section_table
from simrig.report import run_sweep

SPEC = "simrig.plants.cyclopebax:make_cyclopebax_plant"


def _cycle(top_deg: float) -> np.ndarray:
    return np.concatenate([ramp_deg(0.0, top_deg), ramp_deg(top_deg, -top_deg),
                           ramp_deg(-top_deg, 0.0)])


def test_the_ovalising_section_softens_as_it_bends_but_never_turns_back() -> None:
    table = section_table(30.0)
    slope = np.diff(table.moment_Nmm)
    assert np.all(slope > 0.0)
    assert slope[-1] < 0.7 * slope[0]


def test_the_moving_neutral_axis_takes_up_more_the_more_the_section_bends() -> None:
    table = section_table(30.0)
    assert table.takeup_mm[0] == 0.0
    assert np.all(np.diff(table.takeup_mm) > 0.0)


def test_the_reducer_contacts_stiffen_with_load() -> None:
    low = mesh_twist_deg(0.02, 1.0, 0.2) / 0.02
    high = mesh_twist_deg(0.2, 1.0, 0.2) - mesh_twist_deg(0.18, 1.0, 0.2)
    assert mesh_twist_deg(0.0, 1.0, 0.2) == 0.0
    assert high / 0.02 < low


def test_the_rope_grips_its_lumen_harder_drawn_in_than_paying_out() -> None:
    g_in, g_out = grips(0.15, 0.25, 3.0)
    assert g_in > g_out > 1.0


def test_a_held_contact_keeps_its_place_and_a_pulled_one_slides_to_its_grip() -> None:
    held = lumen_contact(1.0, 1.2, 0.9, 20.0, 20.0, 2.0, 1.5, 0.0)
    assert held[0] == 1.0
    y, t0, t1, _ = lumen_contact(1.0, 3.0, 0.9, 20.0, 20.0, 2.0, 1.5, 0.0)
    assert y > 1.0 and t0 == pytest.approx(2.0 * t1)


def test_dead_zone_and_backlash_are_those_of_a_probe_with_the_papers_errors() -> None:
    """Dead zone up to 32 deg: the paper's uncompensated PTPE (58-69 deg) needs 28-31 here."""
    for knob in (0, 1):
        rec = run_sweep(make_cyclopebax_plant(), knob)
        m = measure_dead_zone_backlash(rec.knob_deg, rec.tip_deg)
        assert 10.0 <= m.dead_zone_pos_deg <= 32.0 and 10.0 <= -m.dead_zone_neg_deg <= 32.0
        assert 5.0 <= m.backlash_pos_deg <= 20.0 and 5.0 <= m.backlash_neg_deg <= 20.0


def test_the_tip_follows_the_knob_and_is_straight_at_rest() -> None:
    plant = make_cyclopebax_plant()
    assert np.all(plant.step(0.004, np.zeros(2)).tip_deg == 0.0)
    tip, _ = drive_knob(plant, 0, ramp_deg(0.0, 60.0))
    assert tip[-1] > 40.0
    tip, _ = drive_knob(plant, 1, ramp_deg(0.0, -60.0))
    assert tip[-1] < -40.0


def test_a_closed_knob_cycle_takes_work_from_the_motor() -> None:
    plant = make_cyclopebax_plant()
    path = _cycle(90.0)
    _, torque = drive_knob(plant, 0, path)
    assert float(np.sum(torque[1:] * np.diff(path))) > 0.0


def test_the_knob_feels_more_load_driving_than_back_driven() -> None:
    plant = make_cyclopebax_plant()
    _, up = drive_knob(plant, 0, ramp_deg(0.0, 80.0))
    _, down = drive_knob(plant, 0, ramp_deg(80.0, 79.0))
    assert down[-1] < 0.8 * up[-1]


def test_the_other_plane_bent_narrows_this_planes_dead_zone() -> None:
    def threshold(other_deg: float) -> float:
        plant = make_cyclopebax_plant()
        drive_knob(plant, 1, ramp_deg(0.0, other_deg))
        tip, _ = drive_knob(plant, 0, ramp_deg(0.0, 40.0), other_deg)
        return float(ramp_deg(0.0, 40.0)[np.argmax(tip > 1.0)])

    assert threshold(80.0) < threshold(0.0) - 0.5


def test_the_coupling_keyword_takes_up_this_plane_more_with_the_other_bent() -> None:
    def tip_at_30(coupling: float) -> float:
        plant = make_cyclopebax_plant(coupling=coupling)
        drive_knob(plant, 1, ramp_deg(0.0, 80.0))
        return float(drive_knob(plant, 0, ramp_deg(0.0, 30.0), 80.0)[0][-1])

    def tip_straight(coupling: float) -> float:
        plant = make_cyclopebax_plant(coupling=coupling)
        return float(drive_knob(plant, 0, ramp_deg(0.0, 30.0))[0][-1])

    assert tip_at_30(3.0) > tip_at_30(0.0) + 0.5
    assert tip_straight(3.0) == tip_straight(0.0)  # the other plane straight: no change


def test_an_overload_leaves_a_set_that_stops_growing() -> None:
    plant = make_cyclopebax_plant(knobs=[{"yield_tension_N": 8.0}, {}])
    drive_knob(plant, 0, _cycle(90.0))
    first = plant.set_mm[0][0]
    drive_knob(plant, 0, _cycle(90.0))
    assert first > 0.0
    assert plant.set_mm[0][0] - first < 0.2 * first


def test_slack_grown_by_a_reshape_delays_the_tip() -> None:
    def tip_at_30(plant: CycloPebaxPlant) -> float:
        return float(drive_knob(plant, 0, ramp_deg(0.0, 30.0))[0][-1])

    grown = make_cyclopebax_plant()
    grown.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    assert tip_at_30(grown) < tip_at_30(make_cyclopebax_plant()) - 3.0
    with pytest.raises(ValueError, match="cannot reshape 'rope'"):
        grown.reshape(rope=1.0)


def test_a_unit_is_the_same_catheter_for_the_same_seed() -> None:
    a, b = family_member("cyclopebax", 102).build(), family_member("cyclopebax", 102).build()
    c = family_member("cyclopebax", 102, seed=1).build()
    path = _cycle(70.0)
    tip_a, tq_a = drive_knob(a, 0, path)
    tip_b, tq_b = drive_knob(b, 0, path)
    assert np.array_equal(tip_a, tip_b) and np.array_equal(tq_a, tq_b)
    assert not np.array_equal(tip_a, drive_knob(c, 0, path)[0])


def test_cyclopebax_is_registered_after_jawcrimp_and_held_out() -> None:
    names = list(PLANT_SPECS)
    assert names.index("cyclopebax") == names.index("jawcrimp") + 1
    assert PLANT_ROLE["cyclopebax"] == "held-out"
    assert isinstance(family_member("cyclopebax", 101).build(), CycloPebaxPlant)
    assert set(SCATTER["cyclopebax"]) <= set(family_member("cyclopebax", 0).params["knobs"][0])
    assert isinstance(load_plant(SPEC), CycloPebaxPlant)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"knobs": [{"pin": 1.0}, {}]}, "unknown cyclopebax knob constants: pin"),
        ({"knobs": [{}]}, "cyclopebax takes 2 knobs"),
        ({"knobs": [{"tendon_stiffness_N": 0.0}, {}]}, "tendon_stiffness_N must be > 0"),
        ({"knobs": [{}, {"sheath_friction": -0.1}]}, "sheath_friction must be >= 0"),
        ({"knobs": [{"lay_asymmetry": 1.0}, {}]}, "lay_asymmetry must be < 1"),
        ({"knobs": [{"mesh_friction": 0.6}, {}]}, "mesh_friction must be < 0.5"),
        ({"sheath_curvature_deg": -10.0}, "sheath_curvature_deg must be >= 0"),
        ({"coupling": -1.0}, "coupling must be >= 0"),
    ],
)
def test_bad_constants_are_refused_with_one_clear_line(kwargs: dict[str, object],
                                                       message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        make_cyclopebax_plant(**kwargs)  # type: ignore[arg-type]


def test_bad_step_input_is_refused() -> None:
    with pytest.raises(ValueError, match="dt_s must be >= 0"):
        make_cyclopebax_plant().step(-0.001, np.zeros(2))
    with pytest.raises(ValueError, match="knob_deg must be 2 finite angles"):
        make_cyclopebax_plant().step(0.004, np.array([math.nan, 0.0]))
