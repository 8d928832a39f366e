"""Each switchable effect of the tendon-sheath plant changes the sweep the documented way."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from support.plants import knob1_sweep

from simrig.analysis import DeadZoneBacklash, loaded_slope, measure_dead_zone_backlash
from simrig.plant import PlantLoadError
from simrig.plants.capstan.tendon_sheath import make_tendon_sheath_plant

DT_S = 0.008  # quasi-static plant: a coarser tick keeps these tests fast


def sweep(plant: Any, freq_hz: float = 0.04, cycles: float = 1.5, other_deg: float = 0.0
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return knob1_sweep(plant, freq_hz, cycles, other_deg, DT_S)


def measured(**params: Any) -> DeadZoneBacklash:
    """D and B of a conditioned plant: one cycle first, so the first release is not the virgin
    one (a tension-free plant rests higher after it, docs/plant.md)."""
    other = params.pop("other_deg", 0.0)
    plant = make_tendon_sheath_plant(**params)
    sweep(plant, cycles=1.0, other_deg=other)
    q, tip, _ = sweep(plant, other_deg=other)
    return measure_dead_zone_backlash(q, tip)


@pytest.fixture(scope="module")
def baseline() -> DeadZoneBacklash:
    return measured()


def loop_area(q: np.ndarray, tip: np.ndarray) -> float:
    """Area enclosed by the tip-vs-knob loop over the last full cycle (deg^2)."""
    n = q.size * 2 // 3  # the last 2/3 of a 1.5-cycle sweep is one full cycle
    return float(abs(np.trapezoid(tip[-n:], q[-n:])))


def test_without_coupling_the_other_knob_changes_nothing(baseline: DeadZoneBacklash) -> None:
    assert measured(other_deg=60.0) == baseline


def test_coupling_shifts_the_dead_zone_with_the_other_knob() -> None:
    at = {o: measured(coupling=1.0, other_deg=o) for o in (-90.0, 0.0, 90.0)}
    # Bell-shaped over the other knob's angle: both edges move outwards at the extremes ...
    assert at[-90.0].dead_zone_pos_deg > at[0.0].dead_zone_pos_deg + 3.0
    assert at[90.0].dead_zone_neg_deg < at[0.0].dead_zone_neg_deg - 3.0
    # ... and biased to one side: the positive edge moves more for a negative other knob.
    shift_pos_neg = at[-90.0].dead_zone_pos_deg - at[0.0].dead_zone_pos_deg
    shift_pos_pos = at[90.0].dead_zone_pos_deg - at[0.0].dead_zone_pos_deg
    assert shift_pos_neg > shift_pos_pos + 3.0


def test_coupling_strength_scales_the_shift() -> None:
    weak = measured(coupling=0.5, other_deg=-90.0).dead_zone_pos_deg
    strong = measured(coupling=1.0, other_deg=-90.0).dead_zone_pos_deg
    assert strong > weak


def test_without_rate_dependence_the_loop_does_not_depend_on_speed() -> None:
    slow = loop_area(*sweep(make_tendon_sheath_plant(), freq_hz=0.04)[:2])
    fast = loop_area(*sweep(make_tendon_sheath_plant(), freq_hz=0.2)[:2])
    assert fast == pytest.approx(slow, rel=0.02)


def test_rate_dependence_widens_the_loop_at_higher_speed() -> None:
    """0.3: sheath friction 34 % higher at the 0.2 Hz sweep's peak speed (113 deg/s), 7 % at
    0.04 Hz. With the nominal mu*wrap ~2.1 rad much more nearly locks the tip at 0.2 Hz (k=1:
    B > 120 deg, the loop collapses), which is no longer a wider loop."""
    slow_q, slow_tip, _ = sweep(make_tendon_sheath_plant(rate_dependence=0.3), freq_hz=0.04)
    fast_q, fast_tip, _ = sweep(make_tendon_sheath_plant(rate_dependence=0.3), freq_hz=0.2)
    assert loop_area(fast_q, fast_tip) > 1.05 * loop_area(slow_q, slow_tip)
    slow = measure_dead_zone_backlash(slow_q, slow_tip)
    fast = measure_dead_zone_backlash(fast_q, fast_tip)
    assert fast.backlash_pos_deg > slow.backlash_pos_deg + 3.0


def test_tendon_compliance_lowers_the_loaded_slope_and_widens_the_backlash(
    baseline: DeadZoneBacklash,
) -> None:
    q0, tip0, _ = sweep(make_tendon_sheath_plant())
    q1, tip1, _ = sweep(make_tendon_sheath_plant(tendon_compliance=1.0))
    assert loaded_slope(q1, tip1, 45.0, 80.0)[0] < loaded_slope(q0, tip0, 45.0, 80.0)[0] - 0.1
    assert measure_dead_zone_backlash(q1, tip1).backlash_pos_deg > baseline.backlash_pos_deg + 3.0


def test_sheath_curvature_widens_dead_zone_and_backlash(baseline: DeadZoneBacklash) -> None:
    curved = measured(sheath_curvature_deg=180.0)
    assert curved.dead_zone_pos_deg > baseline.dead_zone_pos_deg + 3.0
    assert curved.dead_zone_neg_deg < baseline.dead_zone_neg_deg - 3.0
    assert curved.backlash_pos_deg > baseline.backlash_pos_deg + 2.0
    assert curved.backlash_neg_deg > baseline.backlash_neg_deg + 2.0


def test_creep_widens_the_dead_zone_over_time() -> None:
    plant = make_tendon_sheath_plant(creep_mm_per_N_s=2e-3)
    first = measure_dead_zone_backlash(*sweep(plant)[:2])
    for _ in range(2):
        sweep(plant)
    later = measure_dead_zone_backlash(*sweep(plant)[:2])
    assert later.dead_zone_pos_deg > first.dead_zone_pos_deg + 2.0
    assert later.dead_zone_neg_deg < first.dead_zone_neg_deg - 2.0


def test_reset_forgets_creep() -> None:
    plant = make_tendon_sheath_plant(creep_mm_per_N_s=2e-3)
    first = measure_dead_zone_backlash(*sweep(plant)[:2])
    sweep(plant)
    plant.reset()
    assert measure_dead_zone_backlash(*sweep(plant)[:2]) == first


def test_knob_stiction_opposes_the_knob_right_after_a_reversal() -> None:
    """The knob's friction breaks loose after a reversal: extra opposing torque over the first
    few degrees of slip, gone once the knob has slid well past handle_slip_deg (3 deg)."""
    q, _, tau = sweep(make_tendon_sheath_plant(), cycles=0.5)
    _, _, tau1 = sweep(
        make_tendon_sheath_plant(knobs=[{"handle_stiction_Nm": 0.012}, {}]), cycles=0.5
    )
    falling = np.gradient(q) < 0
    extra = tau - tau1
    assert extra[falling & (q > 88.5) & (q < 89.7)].max() < -0.01
    assert np.abs(extra[falling & (q > 40.0) & (q < 70.0)]).max() < 0.002


def test_unit_variation_draws_a_different_catheter_per_seed() -> None:
    a = measured(unit_variation=0.15, seed=1)
    b = measured(unit_variation=0.15, seed=2)
    assert a != b
    assert measured(unit_variation=0.15, seed=1) == a


@pytest.mark.parametrize(
    ("params", "name"),
    [
        ({"coupling": -1.0}, "coupling"),
        ({"rate_dependence": float("nan")}, "rate_dependence"),
        ({"sheath_curvature_deg": "big"}, "sheath_curvature_deg"),
        ({"rate_reference_deg_s": 0.0}, "rate_reference_deg_s"),
        ({"no_such_effect": 1.0}, "no_such_effect"),
        ({"knobs": [{"pulley_radius_mm": 0.0}, {}]}, "pulley_radius_mm"),
        ({"knobs": [{}, {"slack_pos_mm": -1.0}]}, "slack_pos_mm"),
        ({"knobs": [{}, {"bogus_mm": 1.0}]}, "bogus_mm"),
        ({"knobs": [{"bend_stiction_ratio": 0.5}, {}]}, "bend_stiction_ratio"),
        ({"knobs": [{}]}, "knobs"),
        ({"n_elements": 1}, "n_elements"),
        ({"n_joints": 2.5}, "n_joints"),
        ({"unit_variation": 0.9}, "unit_variation"),
    ],
)
def test_bad_parameters_are_refused_naming_the_parameter(params: dict[str, Any], name: str) -> None:
    with pytest.raises(ValueError, match=name):
        make_tendon_sheath_plant(**params)


def test_bad_parameters_raise_the_loader_error_type() -> None:
    with pytest.raises(PlantLoadError):
        make_tendon_sheath_plant(coupling=-1.0)
