"""The lumped Dahl-friction plant: the paper's signatures, each effect switch, bad parameters."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from support.plants import knob1_sweep

from simrig.analysis import DeadZoneBacklash, loaded_slope, measure_dead_zone_backlash
from simrig.plant import Plant, PlantLoadError, load_plant
from simrig.plants.lumped import make_lumped_plant

SPEC = "simrig.plants.lumped:make_lumped_plant"
DT_S = 0.008  # quasi-static plant, rate-independent unless viscous drag is on


def sweep(plant: Any, freq_hz: float = 0.04, cycles: float = 1.5, other_deg: float = 0.0,
          dt_s: float = DT_S) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return knob1_sweep(plant, freq_hz, cycles, other_deg, dt_s)


def measured(freq_hz: float = 0.04, cycles: float = 1.5, other_deg: float = 0.0,
             **params: Any) -> tuple[DeadZoneBacklash, float, float]:
    """(D/B, mean loaded slope, loop area of the last cycle)."""
    q, tip, _ = sweep(make_lumped_plant(**params), freq_hz, cycles, other_deg)
    n = round(1.0 / freq_hz / DT_S)
    area = float(abs(np.trapezoid(tip[-n:], q[-n:])))
    return (measure_dead_zone_backlash(q, tip), float(np.mean(loaded_slope(q, tip, 40.0, 85.0))),
            area)


@pytest.fixture(scope="module")
def nominal() -> tuple[DeadZoneBacklash, float, float]:
    return measured()


def test_loads_through_the_plant_factory_spec() -> None:
    assert isinstance(load_plant(SPEC, {"n_lumps": 3}), Plant)


def test_nominal_dead_zone_and_backlash_are_in_the_papers_range(
        nominal: tuple[DeadZoneBacklash, float, float]) -> None:
    m = nominal[0]
    assert 15.0 < m.dead_zone_pos_deg < 30.0 and -30.0 < m.dead_zone_neg_deg < -15.0
    assert 15.0 < m.backlash_pos_deg < 30.0 and 15.0 < m.backlash_neg_deg < 30.0


def test_nominal_loaded_slope_is_in_the_papers_range(
        nominal: tuple[DeadZoneBacklash, float, float]) -> None:
    assert 1.2 <= nominal[1] <= 1.6


def test_torque_falls_within_a_few_degrees_of_a_reversal_while_the_tip_holds() -> None:
    q, tip, tau = sweep(make_lumped_plant(), cycles=1.0)
    i_rev = int(np.argmax(q))
    near = slice(i_rev, i_rev + int(np.argmax(q[i_rev] - q[i_rev:] > 5.0)))
    assert tau[near].min() < 0.5 * tau[i_rev]  # more than half the torque gone in 5 deg
    assert abs(tip[near].min() - tip[i_rev]) < 1.0  # the tip has not moved back yet


def test_torque_is_flat_in_the_dead_zone_and_rises_on_engagement() -> None:
    q, _, tau = sweep(make_lumped_plant(), cycles=1.0)
    first_rise = np.arange(q.size) < int(np.argmax(q))
    flat = tau[first_rise & (q > 2.0) & (q < 15.0)]
    assert np.ptp(flat) < 0.05 * tau.max()
    assert tau[first_rise & (q > 60.0)].min() > 5.0 * np.median(flat)


def test_result_does_not_depend_on_the_step_size() -> None:
    fine = measure_dead_zone_backlash(*sweep(make_lumped_plant(), dt_s=0.001)[:2])
    coarse = measure_dead_zone_backlash(*sweep(make_lumped_plant(), dt_s=0.004)[:2])
    assert np.allclose(fine, coarse, atol=0.5)


def test_without_rate_effect_the_loop_does_not_depend_on_speed(
        nominal: tuple[DeadZoneBacklash, float, float]) -> None:
    fast = measured(freq_hz=0.2)
    assert np.allclose(fast[0], nominal[0], atol=1.0)


def test_reset_repeats_the_run_exactly() -> None:
    plant = make_lumped_plant()
    first = sweep(plant, cycles=0.5)
    plant.reset()
    assert np.array_equal(sweep(plant, cycles=0.5)[1], first[1])


def test_without_coupling_the_other_knob_changes_nothing(
        nominal: tuple[DeadZoneBacklash, float, float]) -> None:
    assert measured(other_deg=60.0)[0] == nominal[0]


def test_coupling_shifts_the_dead_zone_against_the_other_knobs_bend() -> None:
    minus = measured(coupling=1.0, other_deg=-90.0)[0]
    plus = measured(coupling=1.0, other_deg=90.0)[0]
    assert minus.dead_zone_pos_deg - plus.dead_zone_pos_deg > 5.0
    assert minus.dead_zone_neg_deg - plus.dead_zone_neg_deg > 5.0


def test_viscous_drag_widens_the_loop_more_at_higher_speed(
        nominal: tuple[DeadZoneBacklash, float, float]) -> None:
    slow = measured(viscous_N_s_per_m=40.0)
    fast = measured(freq_hz=0.2, viscous_N_s_per_m=40.0)
    assert slow[2] > 1.05 * nominal[2]
    assert fast[2] > 1.5 * slow[2]
    assert fast[0].backlash_pos_deg > nominal[0].backlash_pos_deg + 4.0


def test_tendon_compliance_lowers_the_slope_and_lengthens_the_backlash(
        nominal: tuple[DeadZoneBacklash, float, float]) -> None:
    m, slope, _ = measured(tendon_compliance=1.0)
    assert slope < nominal[1] - 0.2
    assert m.backlash_pos_deg > nominal[0].backlash_pos_deg + 5.0


def test_sheath_curvature_widens_dead_zone_and_backlash(
        nominal: tuple[DeadZoneBacklash, float, float]) -> None:
    m, slope, _ = measured(sheath_curvature_deg=180.0)
    assert m.dead_zone_pos_deg > nominal[0].dead_zone_pos_deg + 5.0
    assert m.backlash_pos_deg > nominal[0].backlash_pos_deg + 4.0
    assert slope < nominal[1]


def test_creep_slackens_the_loaded_tendon_over_cycles() -> None:
    plain = measured(cycles=3.5)[0]
    crept = measured(cycles=3.5, creep_compliance_mm_per_N=0.05, creep_time_s=20.0)[0]
    assert crept.dead_zone_pos_deg > plain.dead_zone_pos_deg + 0.5


def test_tendons_never_push_under_random_motion_with_every_effect_on() -> None:
    plant = make_lumped_plant(coupling=1.0, viscous_N_s_per_m=20.0, tendon_compliance=0.5,
                              sheath_curvature_deg=90.0, creep_compliance_mm_per_N=0.01)
    rng = np.random.default_rng(3)
    q = np.cumsum(rng.normal(0.0, 0.8, (3000, 2)), axis=0).clip(-90.0, 90.0)
    for row in q:
        step = plant.step(0.004, row)
        assert np.all(np.isfinite(step.tip_deg)) and np.all(np.abs(step.tip_deg) < 180.0)
        assert np.all(plant.tendon_tension_N() >= 0.0)


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"knobs": [{"pulley_radius_mm": 0.0}, {}]}, "knobs[0].pulley_radius_mm must be > 0"),
        ({"knobs": [{}, {"sheath_friction": -0.1}]}, "knobs[1].sheath_friction must be >= 0"),
        ({"knobs": [{"toe_mm": float("nan")}, {}]}, "knobs[0].toe_mm must be finite"),
        ({"knobs": [{"slack_pos_mm": "2"}, {}]}, "knobs[0].slack_pos_mm must be a number"),
        ({"knobs": [{"bogus": 1.0}, {}]}, "knobs[0]: unknown parameter 'bogus'"),
        ({"knobs": [{}]}, "knobs must list 2 knobs"),
        ({"n_lumps": 0}, "n_lumps must be an integer in 1..20"),
        ({"coupling": -1.0}, "coupling must be >= 0"),
        ({"creep_time_s": 0.0}, "creep_time_s must be > 0"),
        ({"foo": 1.0}, "unknown plant parameter 'foo'"),
    ],
)
def test_bad_parameters_are_refused_with_a_named_error(params: dict[str, Any],
                                                       message: str) -> None:
    with pytest.raises(PlantLoadError, match=message.replace("[", r"\[").replace("]", r"\]")
                       .replace(".", r"\.")):
        load_plant(SPEC, params)
