"""The twistshaft plant: stable, deterministic, symmetric, resettable; its mechanisms act."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from simrig.analysis import measure_dead_zone_backlash
from simrig.plant import PlantLoadError, load_plant
from simrig.plants.twistshaft import TwistShaftPlant, make_twistshaft_plant
from simrig.plants.twistshaft.tendon import LumenTendon

SPEC = "simrig.plants.twistshaft:make_twistshaft_plant"
STRAIGHT_LUMENS = {"lumen_angle_error_deg": 0.0, "lumen_helix_deg": 0.0}
"""Lumens exactly in their planes and without helix: no plane couples to the other."""


def _sweep(plant: TwistShaftPlant, dt_s: float, amplitude_deg: float = 90.0,
           period_s: float = 8.0, other_deg: float = 0.0, cycles: float = 1.25
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Knob 1 on a sine from 0; tip angles (both planes) and knob-1 torque."""
    t = np.arange(dt_s, cycles * period_s + dt_s / 2, dt_s)
    q = amplitude_deg * np.sin(2 * np.pi * t / period_s)
    tip = np.empty((q.size, 2))
    torque = np.empty_like(q)
    for i, qi in enumerate(q):
        step = plant.step(dt_s, np.array([qi, other_deg]))
        tip[i], torque[i] = step.tip_deg, step.knob_torque_Nm[0]
    return q, tip, torque


def test_a_sweep_stays_finite_and_close_at_plant_steps_from_100_us_to_4_ms() -> None:
    ends = []
    for dt_s in (1e-4, 1e-3, 4e-3):
        _, tip, torque = _sweep(make_twistshaft_plant(), dt_s, period_s=2.0)
        assert np.isfinite(tip).all() and np.isfinite(torque).all()
        ends.append((tip[-1, 0], torque[-1]))
    assert np.allclose(ends, ends[0], atol=0.05)


def test_the_same_inputs_give_the_same_outputs() -> None:
    a = _sweep(make_twistshaft_plant(), 0.004)
    b = _sweep(make_twistshaft_plant(), 0.004)
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))


def test_a_knob_bends_the_tip_mirror_symmetrically() -> None:
    _, up, tq_up = _sweep(make_twistshaft_plant(), 0.004)
    _, down, tq_down = _sweep(make_twistshaft_plant(), 0.004, amplitude_deg=-90.0)
    assert np.allclose(up, -down, atol=1e-6)
    assert np.allclose(tq_up, -tq_down, atol=1e-9)


def test_reset_returns_the_tip_to_straight_and_unloaded() -> None:
    plant = make_twistshaft_plant()
    _sweep(plant, 0.004, cycles=0.3)
    plant.reset()
    step = plant.step(0.0, np.array([0.0, 0.0]))
    assert np.array_equal(step.tip_deg, [0.0, 0.0])
    assert np.array_equal(step.knob_torque_Nm, [0.0, 0.0])
    assert plant.twist_rad == 0.0 and plant.temperature_C == plant.shaft.start_temperature_C


def test_the_nominal_unit_has_a_dead_zone_and_backlash_of_the_papers_order() -> None:
    q, tip, _ = _sweep(make_twistshaft_plant(), 0.004, cycles=2.25)
    m = measure_dead_zone_backlash(q, tip[:, 0])
    assert 15.0 < m.dead_zone_pos_deg < 40.0 and 15.0 < -m.dead_zone_neg_deg < 40.0
    assert 5.0 < m.backlash_pos_deg < 25.0 and 5.0 < m.backlash_neg_deg < 25.0


@pytest.mark.parametrize(("dt_s", "knob"), [(-0.001, [0.0, 0.0]), (0.004, [float("nan"), 0.0]),
                                            (0.004, [1.0]), (0.004, "ab")])
def test_bad_step_input_is_refused(dt_s: float, knob: Any) -> None:
    with pytest.raises(ValueError):
        make_twistshaft_plant().step(dt_s, knob)


@pytest.mark.parametrize(("params", "message"), [
    ({"knobs": [{"pulley_radius_mm": 0.0}, {}]}, "knob 0: pulley_radius_mm must be > 0"),
    ({"knobs": [{}, {"bogus": 1.0}]}, "knob 1: unknown constant 'bogus'"),
    ({"knobs": [{}]}, "knobs must list 2 knobs"),
    ({"knobs": [{"friction_exponent": 1.5}, {}]}, r"friction_exponent must be in \[0.3, 1\]"),
    ({"sheath_curvature_deg": -5.0}, "sheath_curvature_deg must be >= 0"),
    ({"foo": 1}, "unknown shaft constant 'foo'"),
])
def test_bad_parameters_are_refused_by_name(params: dict[str, Any], message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        load_plant(SPEC, params)


def test_the_lumens_helix_twists_the_shaft_and_turns_the_bending_plane() -> None:
    straight = make_twistshaft_plant(knobs=[STRAIGHT_LUMENS, STRAIGHT_LUMENS])
    helix = {**STRAIGHT_LUMENS, "lumen_helix_deg": 1.5}
    twisted = make_twistshaft_plant(knobs=[helix, helix])
    _, tip_straight, _ = _sweep(straight, 0.004, cycles=0.25)
    _, tip_twisted, _ = _sweep(twisted, 0.004, cycles=0.25)
    assert np.max(np.abs(tip_straight[:, 1])) < 1e-9
    assert np.max(np.abs(tip_twisted[:, 1])) > 1.0


def test_the_shafts_friction_keeps_part_of_the_twist_after_the_load_is_gone() -> None:
    for friction_Nm, kept in ((0.0002, True), (0.0, False)):
        plant = make_twistshaft_plant(torsion_friction_Nm=friction_Nm)
        _sweep(plant, 0.004, cycles=0.5)  # out to +90 and back to 0
        assert (plant.twist_rad > 1e-3) is kept


def test_an_off_plane_lumen_bends_the_other_plane_without_any_twist() -> None:
    off = {**STRAIGHT_LUMENS, "lumen_angle_error_deg": 2.0}
    _, tip, _ = _sweep(make_twistshaft_plant(knobs=[off, off]), 0.004, cycles=0.25)
    assert tip[-1, 1] == pytest.approx(tip[-1, 0] * np.tan(np.radians(2.0)), rel=0.05)


def _tip_at_full_turn(plant: TwistShaftPlant, wait_s: float) -> float:
    for _ in range(round(wait_s / 0.1)):
        plant.step(0.1, np.array([0.0, 0.0]))
    q = np.linspace(0.0, 90.0, 400)
    for qi in q:
        tip = plant.step(0.004, np.array([qi, 0.0])).tip_deg
    return float(tip[0])


def test_the_warmed_up_catheter_bends_further_for_the_same_turn() -> None:
    cold = _tip_at_full_turn(make_twistshaft_plant(), 0.0)
    warm = _tip_at_full_turn(make_twistshaft_plant(), 300.0)
    assert warm > cold + 1.0
    at_room = _tip_at_full_turn(make_twistshaft_plant(body_temperature_C=24.0), 0.0)
    waited = _tip_at_full_turn(make_twistshaft_plant(body_temperature_C=24.0), 300.0)
    assert waited == pytest.approx(at_room, abs=1e-9)


def test_the_lumen_friction_coefficient_falls_with_load_only_below_exponent_one() -> None:
    def share(n: float, tension_N: float) -> float:
        t = LumenTendon(kp_N_mm=10.0, kd_N_mm=10.0, toe_mm=0.1, slack_mm=0.0, wrap_rad=2.0,
                        mu=0.5, n=n, load_N=5.0, drag_N=0.0)
        return t._capacity(tension_N, tension_N, 0.5)[0] / (2 * tension_N)
    assert share(0.67, 20.0) < 0.8 * share(0.67, 0.5)
    assert share(1.0, 20.0) == pytest.approx(share(1.0, 0.5))


def test_reshaping_mid_run_widens_the_dead_zone_and_refuses_bad_changes() -> None:
    before = _sweep(make_twistshaft_plant(), 0.004, cycles=2.25)
    plant = make_twistshaft_plant()
    plant.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)), sheath_curvature_deg=30.0)
    after = _sweep(plant, 0.004, cycles=2.25)
    d_before = measure_dead_zone_backlash(before[0], before[1][:, 0]).dead_zone_pos_deg
    d_after = measure_dead_zone_backlash(after[0], after[1][:, 0]).dead_zone_pos_deg
    assert d_after > d_before + 2.0  # 0.5 mm on the 8 mm drum is 3.6 knob deg
    with pytest.raises(ValueError, match="slack_delta_mm"):
        plant.reshape(slack_delta_mm=((0.5,), (0.5, 0.5)))
