"""The segments plant (written blind): magnitudes, tick independence, determinism, symmetry,
reset, coupling, reshaping and refusals."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from support.plants import knob1_sweep

from simrig.analysis import DeadZoneBacklash, loaded_slope, measure_dead_zone_backlash
from simrig.plant import Plant, PlantLoadError, load_plant
from simrig.plants.segments import make_segments_plant

SPEC = "simrig.plants.segments:make_segments_plant"
DT_S = 0.016  # quasi-static and tick-independent (tested): a coarse tick keeps the tests fast
SYMMETRIC = [{"slack_pos_mm": 2.5, "slack_neg_mm": 2.5}, {"slack_pos_mm": 2.5, "slack_neg_mm": 2.5}]


def measured(other_deg: float = 0.0, **params: Any) -> tuple[DeadZoneBacklash, float]:
    q, tip, _ = knob1_sweep(make_segments_plant(**params), 0.04, 1.5, other_deg, DT_S)
    return measure_dead_zone_backlash(q, tip), float(np.mean(loaded_slope(q, tip, 40.0, 85.0)))


@pytest.fixture(scope="module")
def nominal() -> tuple[DeadZoneBacklash, float]:
    return measured()


def run(plant: Any, dt_s: float, duration_s: float) -> np.ndarray:
    """Both knobs on a fast excursion (0 -> 80 -> -60 deg, the other knob opposite); tip rows."""
    t = np.arange(dt_s, duration_s + 1e-12, dt_s)
    q = 80.0 * np.sin(2.0 * np.pi * t / duration_s) - 20.0 * (1.0 - np.cos(2.0 * np.pi * t /
                                                                          duration_s))
    rows = [plant.step(dt_s, np.array([qi, -0.5 * qi])).tip_deg for qi in q]
    return np.array(rows)


def test_loads_through_the_plant_factory_spec() -> None:
    assert isinstance(load_plant(SPEC, {"n_elements": 6}), Plant)


def test_nominal_dead_zone_and_backlash_are_tens_of_knob_degrees(
        nominal: tuple[DeadZoneBacklash, float]) -> None:
    m = nominal[0]
    assert 15.0 < m.dead_zone_pos_deg < 30.0 and -30.0 < m.dead_zone_neg_deg < -15.0
    assert 15.0 < m.backlash_pos_deg < 30.0 and 15.0 < m.backlash_neg_deg < 30.0


def test_nominal_loaded_slope_is_in_the_papers_range(
        nominal: tuple[DeadZoneBacklash, float]) -> None:
    assert 1.2 <= nominal[1] <= 1.6


def test_tip_reaches_sixty_to_ninety_degrees_at_full_knob() -> None:
    tip = knob1_sweep(make_segments_plant(), 0.04, 1.0, 0.0, DT_S)[1]
    assert 60.0 <= tip.max() <= 95.0 and -95.0 <= tip.min() <= -60.0


def test_the_tick_does_not_change_the_tip_from_100_us_to_4_ms() -> None:
    fine = run(make_segments_plant(), 1e-4, 1.0)
    coarse = run(make_segments_plant(), 4e-3, 1.0)
    assert np.all(np.isfinite(fine)) and np.all(np.isfinite(coarse))
    assert np.max(np.abs(fine[39::40] - coarse)) < 1.0


def test_same_inputs_give_the_same_tip_and_torque() -> None:
    a, b = make_segments_plant(), make_segments_plant()
    for qi in np.linspace(0.0, 70.0, 300):
        sa, sb = a.step(0.004, np.array([qi, -qi])), b.step(0.004, np.array([qi, -qi]))
    assert np.array_equal(sa.tip_deg, sb.tip_deg)
    assert np.array_equal(sa.knob_torque_Nm, sb.knob_torque_Nm)


def test_a_symmetric_catheter_mirrors_its_tip_and_torque() -> None:
    a, b = make_segments_plant(SYMMETRIC), make_segments_plant(SYMMETRIC)
    for qi in 80.0 * np.sin(np.linspace(0.0, 3.0, 400)):
        sa, sb = a.step(0.004, np.array([qi, 0.5 * qi])), b.step(0.004, np.array([-qi, -0.5 * qi]))
        assert np.allclose(sa.tip_deg, -sb.tip_deg, atol=1e-9)
        assert np.allclose(sa.knob_torque_Nm, -sb.knob_torque_Nm, atol=1e-12)


def test_reset_returns_to_straight_and_unloaded() -> None:
    plant = make_segments_plant()
    knob1_sweep(plant, 0.2, 0.75, 40.0, 0.004)
    plant.reset()
    step = plant.step(0.004, np.array([0.0, 0.0]))
    assert np.allclose(step.tip_deg, 0.0) and np.allclose(step.knob_torque_Nm, 0.0)
    again = knob1_sweep(plant, 0.2, 0.5, 0.0, 0.004)[1]
    assert np.array_equal(again, knob1_sweep(make_segments_plant(), 0.2, 0.5, 0.0, 0.004)[1])


def test_torque_is_flat_in_the_dead_zone_and_falls_within_five_degrees_of_a_reversal() -> None:
    q, tip, tau = knob1_sweep(make_segments_plant(), 0.04, 1.0, 0.0, DT_S)
    rising = (q > -12.0) & (q < 12.0) & (np.gradient(q) > 0) & (np.arange(q.size) > q.size // 2)
    assert np.ptp(tau[rising]) < 0.1 * tau.max()
    i_rev = int(np.argmax(q))
    near = i_rev + int(np.argmax(q[i_rev] - q[i_rev:] > 5.0))
    assert tau[near] < 0.5 * tau[i_rev]
    assert abs(tip[near] - tip[i_rev]) < 1.0


def test_without_coupling_the_other_knob_changes_nothing() -> None:
    a = knob1_sweep(make_segments_plant(coupling=0.0), 0.2, 0.75, 0.0, 0.004)[1]
    b = knob1_sweep(make_segments_plant(coupling=0.0), 0.2, 0.75, 80.0, 0.004)[1]
    assert np.array_equal(a, b)


def test_the_nominal_coupling_moves_the_dead_zone_a_little() -> None:
    base = measured(0.0)[0].dead_zone_pos_deg
    bent = measured(-90.0)[0].dead_zone_pos_deg
    assert 0.5 < abs(bent - base) < 10.0


def test_a_curved_sheath_and_more_slack_widen_the_dead_zone(
        nominal: tuple[DeadZoneBacklash, float]) -> None:
    assert measured(sheath_curvature_deg=120.0)[0].dead_zone_pos_deg > \
        nominal[0].dead_zone_pos_deg + 2.0
    plant = make_segments_plant()
    plant.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    q, tip, _ = knob1_sweep(plant, 0.04, 1.5, 0.0, DT_S)
    assert measure_dead_zone_backlash(q, tip).dead_zone_pos_deg > nominal[0].dead_zone_pos_deg + 3


@pytest.mark.parametrize(("dt_s", "knob"), [(-0.001, [0.0, 0.0]), (0.004, [float("nan"), 0.0]),
                                            (0.004, [1.0]), (0.004, "ab")])
def test_bad_step_input_is_refused(dt_s: float, knob: Any) -> None:
    with pytest.raises(ValueError):
        make_segments_plant().step(dt_s, knob)


@pytest.mark.parametrize(("params", "message"), [
    ({"knobs": [{"pulley_radius_mm": 0.0}, {}]}, r"knobs\[0\].pulley_radius_mm must be > 0"),
    ({"knobs": [{}, {"bogus": 1.0}]}, r"knobs\[1\]: unknown parameter 'bogus'"),
    ({"knobs": [{}]}, "knobs must be a list of 2 mappings"),
    ({"n_elements": 1}, "n_elements must be an integer in 2..40"),
    ({"coupling": -1.0}, "coupling must be >= 0"),
    ({"foo": 1}, "unknown plant parameter 'foo'"),
])
def test_bad_parameters_are_refused_by_name(params: dict[str, Any], message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        load_plant(SPEC, params)
