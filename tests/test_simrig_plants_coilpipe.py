"""The coil-pipe plant (fourth, written blind): signatures, its mechanisms, numerics, bad input."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from support.plants import knob1_sweep

from simrig.analysis import DeadZoneBacklash, loaded_slope, measure_dead_zone_backlash
from simrig.plant import Plant, PlantLoadError, load_plant
from simrig.plants.coilpipe import make_coilpipe_plant

SPEC = "simrig.plants.coilpipe:make_coilpipe_plant"
DT_S = 0.004


def db_of(freq_hz: float = 0.04, other_deg: float = 0.0, **params: Any) -> DeadZoneBacklash:
    q, tip, _ = knob1_sweep(make_coilpipe_plant(**params), freq_hz, 1.5, other_deg, DT_S)
    return measure_dead_zone_backlash(q, tip)


@pytest.fixture(scope="module")
def nominal() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return knob1_sweep(make_coilpipe_plant(), 0.04, 1.5, 0.0, DT_S)


def test_loads_through_the_plant_factory_spec() -> None:
    assert isinstance(load_plant(SPEC, {"sections": 3}), Plant)


def test_nominal_dead_zone_and_backlash_are_tens_of_knob_degrees(nominal: Any) -> None:
    q, tip, _ = nominal
    db = measure_dead_zone_backlash(q, tip)
    assert 12.0 < db.dead_zone_pos_deg < 30.0 and -30.0 < db.dead_zone_neg_deg < -12.0
    assert 10.0 < db.backlash_pos_deg < 30.0 and 10.0 < db.backlash_neg_deg < 30.0


def test_nominal_slope_and_tip_range_are_the_papers(nominal: Any) -> None:
    q, tip, _ = nominal
    slopes = np.asarray(loaded_slope(q, tip, 40.0, 85.0))
    assert np.all((slopes > 1.15) & (slopes < 1.6))
    assert 60.0 < tip.max() < 95.0 and -95.0 < tip.min() < -60.0


def test_torque_falls_within_a_few_degrees_of_a_reversal_while_the_tip_holds(
        nominal: Any) -> None:
    q, tip, tau = nominal
    top = int(np.argmax(q))
    after = top + int(np.argmax(q[top:] < q[top] - 5.0))
    assert abs(tau[after]) < 0.5 * abs(tau[top])
    assert abs(tip[after] - tip[top]) < 1.0


def test_the_tip_is_the_same_at_a_tenth_of_a_millisecond_and_at_four() -> None:
    t_s = 2.0
    answers = []
    for dt in (1e-4, 4e-3):
        plant = make_coilpipe_plant()
        n = round(t_s / dt)
        for i in range(1, n + 1):
            s = np.sin(np.pi * i / n)
            step = plant.step(dt, np.array([85.0 * s, -60.0 * s * s]))
        answers.append(step.tip_deg)
    assert np.allclose(answers[0], answers[1], atol=1.0)


def test_two_plants_given_the_same_input_answer_the_same() -> None:
    a = knob1_sweep(make_coilpipe_plant(), 0.1, 1.0, 30.0, DT_S)
    b = knob1_sweep(make_coilpipe_plant(), 0.1, 1.0, 30.0, DT_S)
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))


def test_a_symmetric_catheter_answers_a_mirrored_input_mirrored() -> None:
    q, tip, tau = knob1_sweep(make_coilpipe_plant(), 0.1, 1.0, 40.0, DT_S)
    plant = make_coilpipe_plant()
    for qi, ti, ci in zip(q, tip, tau, strict=True):
        step = plant.step(DT_S, np.array([-qi, -40.0]))
        assert step.tip_deg[0] == pytest.approx(-ti, abs=1e-6)
        assert step.knob_torque_Nm[0] == pytest.approx(-ci, abs=1e-8)


def test_reset_returns_to_straight_and_repeats_the_run() -> None:
    plant = make_coilpipe_plant()
    first = knob1_sweep(plant, 0.1, 0.75, 50.0, DT_S)
    plant.reset()
    step = plant.step(DT_S, np.zeros(2))
    assert np.allclose(step.tip_deg, 0.0) and np.allclose(step.knob_torque_Nm, 0.0, atol=1e-9)
    plant.reset()
    again = knob1_sweep(plant, 0.1, 0.75, 50.0, DT_S)
    assert all(np.array_equal(x, y) for x, y in zip(first, again, strict=True))


def test_a_loaded_other_knob_widens_the_dead_zone_through_the_compressed_shaft() -> None:
    soft = db_of(other_deg=90.0, coupling_mm_per_rad2=0.0)
    stiff = db_of(other_deg=90.0, coupling_mm_per_rad2=0.0, shaft_stiffness_N_per_mm=1e6)
    assert soft.dead_zone_pos_deg > stiff.dead_zone_pos_deg + 1.0


def test_the_tip_creeps_on_while_the_knob_holds() -> None:
    plant = make_coilpipe_plant()
    for q in np.linspace(0.0, 80.0, 400):
        start = plant.step(DT_S, np.array([q, 0.0])).tip_deg[0]
    for _ in range(2500):
        held = plant.step(DT_S, np.array([80.0, 0.0])).tip_deg[0]
    assert held > start + 0.3


def test_more_slack_mid_run_widens_the_dead_zone(nominal: Any) -> None:
    plant = make_coilpipe_plant()
    plant.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    q, tip, _ = knob1_sweep(plant, 0.04, 1.5, 0.0, DT_S)
    before = measure_dead_zone_backlash(*nominal[:2]).dead_zone_pos_deg
    assert measure_dead_zone_backlash(q, tip).dead_zone_pos_deg > before + 2.0


def test_a_curved_sheath_widens_dead_zone_and_backlash(nominal: Any) -> None:
    curved = db_of(sheath_curvature_deg=180.0)
    straight = measure_dead_zone_backlash(*nominal[:2])
    assert curved.dead_zone_pos_deg > straight.dead_zone_pos_deg + 1.0
    assert curved.backlash_pos_deg > straight.backlash_pos_deg + 1.0


@pytest.mark.parametrize(("dt_s", "knob"), [(-0.001, [0.0, 0.0]), (0.004, [float("nan"), 0.0]),
                                            (0.004, [1.0]), (0.004, "ab")])
def test_bad_step_input_is_refused(dt_s: float, knob: Any) -> None:
    with pytest.raises(ValueError):
        make_coilpipe_plant().step(dt_s, knob)


@pytest.mark.parametrize(("params", "message"), [
    ({"knobs": [{"pulley_radius_mm": 0.0}, {}]}, r"knobs\[0\]\.pulley_radius_mm must be > 0"),
    ({"knobs": [{}, {"sheath_friction": -0.1}]}, r"knobs\[1\]\.sheath_friction must be >= 0"),
    ({"knobs": [{"toe_mm": float("nan")}, {}]}, r"knobs\[0\]\.toe_mm must be a finite number"),
    ({"knobs": [{}, {"bogus": 1.0}]}, r"knobs\[1\]: unknown parameter 'bogus'"),
    ({"knobs": [{}]}, "knobs must be a list of 2 mappings"),
    ({"sections": 0}, "sections must be an integer in 1..12"),
    ({"shaft_stiffness_N_per_mm": 0.0}, "shaft_stiffness_N_per_mm must be > 0"),
    ({"foo": 1}, "unknown coilpipe parameter 'foo'"),
])
def test_bad_parameters_are_refused_by_name(params: dict[str, Any], message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        load_plant(SPEC, params)


def test_an_unknown_shape_change_is_refused() -> None:
    with pytest.raises(ValueError, match="cannot change"):
        make_coilpipe_plant().reshape(colour="red")
