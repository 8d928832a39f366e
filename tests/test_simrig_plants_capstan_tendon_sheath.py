"""The built-in tendon-sheath plant shows the paper's signatures on a +-90 deg, 0.04 Hz sweep."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray

from simrig.analysis import loaded_slope, measure_dead_zone_backlash
from simrig.family import family_member
from simrig.plant import Plant, load_plant
from simrig.plants.capstan import tendon_sheath
from simrig.plants.capstan.tendon_sheath import TendonSheathPlant, make_tendon_sheath_plant
from simrig.report import SweepRecord
from simrig.report import run_sweep as report_sweep

DT_S = 0.004  # 250 Hz ticks
FloatArray = NDArray[np.float64]


def run_sweep(plant: Plant, knob: int = 0, **kwargs: Any) -> SweepRecord:
    """The report's sweep at 250 Hz ticks (it resets the plant first)."""
    return report_sweep(plant, knob, dt_s=DT_S, **kwargs)


@pytest.fixture(scope="module", params=[0, 1], ids=["phi1", "phi2"])
def default_sweep(request: pytest.FixtureRequest) -> SweepRecord:
    return run_sweep(make_tendon_sheath_plant(), knob=request.param)


def test_factory_builds_a_plant_through_the_config_loader() -> None:
    plant = load_plant("simrig.plants.capstan:make_tendon_sheath_plant", {"coupling": 1.0})
    assert isinstance(plant, TendonSheathPlant)
    assert isinstance(plant, Plant)


def test_straight_and_unloaded_at_rest() -> None:
    step = make_tendon_sheath_plant().step(DT_S, np.zeros(2))
    assert np.allclose(step.tip_deg, 0.0)
    assert np.allclose(step.knob_torque_Nm, 0.0)


def test_sweep_shows_a_dead_zone_on_both_sides(default_sweep: SweepRecord) -> None:
    m = measure_dead_zone_backlash(default_sweep.knob_deg, default_sweep.tip_deg)
    assert 15.0 <= m.dead_zone_pos_deg <= 30.0
    assert -30.0 <= m.dead_zone_neg_deg <= -15.0


def test_sweep_shows_backlash_after_both_reversals(default_sweep: SweepRecord) -> None:
    """The tip holds for tens of degrees after each reversal, about equally on both sides."""
    m = measure_dead_zone_backlash(default_sweep.knob_deg, default_sweep.tip_deg)
    assert 12.0 <= m.backlash_pos_deg <= 30.0
    assert 12.0 <= m.backlash_neg_deg <= 30.0
    assert abs(m.backlash_pos_deg - m.backlash_neg_deg) < 3.0


def test_tip_slope_in_the_loaded_region_is_in_the_papers_range(default_sweep: SweepRecord) -> None:
    """The paper's four catheters: 1.32 +- 0.12; stretch keeps it below the pulley/offset ratio."""
    pos, neg = loaded_slope(default_sweep.knob_deg, default_sweep.tip_deg, 40.0, 85.0)
    assert 1.2 <= pos <= 1.7
    assert 1.2 <= neg <= 1.7
    assert pos == pytest.approx(neg, rel=0.05)
    kinematic = 6.0 / 2.43  # pulley radius over the smaller tendon offset: an inextensible tendon
    assert max(pos, neg) < 0.8 * kinematic


def backlash_end_corner_deg(s: SweepRecord) -> float:
    """Knob travel from the tip leaving the backlash plateau (after the second positive
    reversal) to the tip reaching 90 % of the releasing branch's slope."""
    falling = (s.t_s > 31.25) & (s.t_s < 37.5) & (s.knob_deg > 30.0)
    q, y = s.knob_deg[falling], s.tip_deg[falling]
    start = int(np.flatnonzero(y < y[0] - 0.05)[0])
    branch = (
        np.interp(q[start] - 12.0, q[::-1], y[::-1]) - np.interp(q[start] - 17.0, q[::-1], y[::-1])
    ) / 5.0
    slope = np.gradient(y, q)  # both fall: positive
    full = start + int(np.flatnonzero(slope[start:] >= 0.9 * branch)[0])
    return float(q[start] - q[full])


@pytest.mark.parametrize("knob", [0, 1], ids=["phi1", "phi2"])
def test_backlash_end_is_rounded_by_the_bending_joints(knob: int) -> None:
    """The joints give way one after another, so the tip speeds up over a stretch of knob travel
    instead of snapping onto the releasing line; without joint friction it is a kink. (With the
    steel tendon of the nominal unit the corner shrinks to a kink either way, so this is measured
    on the compliant-tendon variant, where it spans ~0.5 deg: docs/plant.md.)"""
    compliant = family_member("capstan", 0, "compliant-tendon").params["knobs"]
    nominal = run_sweep(make_tendon_sheath_plant(knobs=compliant), knob)
    no_joint_friction = [{**k, "bend_friction_Nm": 0.0} for k in compliant]
    frictionless = run_sweep(make_tendon_sheath_plant(knobs=no_joint_friction), knob)
    assert backlash_end_corner_deg(nominal) > 0.4
    assert backlash_end_corner_deg(frictionless) < 0.2


def test_torque_is_flat_and_small_in_the_dead_zone(default_sweep: SweepRecord) -> None:
    s = default_sweep
    rising_dz = (np.gradient(s.knob_deg) > 0) & (np.abs(s.knob_deg) < 10.0) & (s.t_s > 12.5)
    tau = s.torque_Nm[rising_dz]
    peak = np.max(np.abs(s.torque_Nm))
    assert np.ptp(tau) < 0.02 * peak
    assert np.max(np.abs(tau)) < 0.06 * peak


def test_torque_rises_once_the_tendon_engages(default_sweep: SweepRecord) -> None:
    s = default_sweep
    second_cycle = s.t_s > 25.0
    loading = (
        second_cycle & (np.gradient(s.knob_deg) > 0) & (s.knob_deg > 35.0) & (s.knob_deg < 88.0)
    )
    q, tau = s.knob_deg[loading], s.torque_Nm[loading]
    assert np.all(np.diff(tau) > -0.01 * tau.max())  # at most a slight stick-slip ripple
    assert tau.max() > 0.05
    assert np.corrcoef(q, tau)[0, 1] > 0.99


def test_knob_torque_is_of_order_0_05_to_0_6_Nm(default_sweep: SweepRecord) -> None:
    assert 0.05 <= np.max(np.abs(default_sweep.torque_Nm)) <= 0.6


def release_after_reversal(s: SweepRecord) -> tuple[FloatArray, FloatArray, float, float]:
    """Knob and torque for 12 s after the first positive reversal, the torque's released level
    (median while the tip falls freely) and the tip's backlash B_pos."""
    m = measure_dead_zone_backlash(s.knob_deg, s.tip_deg)
    i_rev = int(np.argmax(s.knob_deg[: int(25.0 / DT_S)]))
    after = slice(i_rev, i_rev + int(12.0 / DT_S))
    q, tau = s.knob_deg[after], s.torque_Nm[after]
    released = (q < 90.0 - m.backlash_pos_deg - 2.0) & (q > m.dead_zone_pos_deg + 5.0)
    return q, tau, float(np.median(tau[released])), m.backlash_pos_deg


def settled_after_deg(q: FloatArray, tau: FloatArray, level: float, tol_Nm: float) -> float:
    """Knob travel from the reversal (90 deg) until the torque is within tol of its level."""
    return float(90.0 - q[np.flatnonzero(np.abs(tau - level) < tol_Nm)[0]])


def test_torque_decays_through_the_backlash_then_stays_near_zero(
    default_sweep: SweepRecord,
) -> None:
    """Straight handle (the paper's Lesson 2): after a reversal the knob still feels the sheath
    unloading, so the torque falls through the whole backlash and joins its released level
    (near zero) about where the tip starts to move back."""
    s = default_sweep
    peak = float(np.max(s.torque_Nm))
    q, tau, level, backlash = release_after_reversal(s)
    swing = peak - level
    assert tau[0] > 0.8 * peak
    assert np.interp(87.0, q[::-1], tau[::-1]) - level > 0.15 * swing  # 3 deg on: far from done
    assert np.interp(90.0 - backlash / 2, q[::-1], tau[::-1]) - level > 0.05 * swing
    settled = settled_after_deg(q, tau, level, 0.02 * peak)
    assert 0.5 * backlash < settled < backlash + 2.0
    released = (q < 90.0 - backlash - 2.0) & (q > 30.0)
    assert np.max(np.abs(tau[released])) < 0.1 * peak
    assert abs(level) < 0.06 * peak


@pytest.mark.parametrize("knob", [0, 1], ids=["phi1", "phi2"])
def test_a_routed_handle_drops_the_torque_within_a_few_degrees(knob: int) -> None:
    """Guide pins right after the pulley (a capstan there) let the pulley tension collapse at
    once: the knob no longer feels the sheath unloading, while the tip still holds as long."""
    s = run_sweep(make_tendon_sheath_plant(knobs=[{"routing_wrap_deg": 360.0}] * 2), knob)
    peak = float(np.max(s.torque_Nm))
    q, tau, level, backlash = release_after_reversal(s)
    assert backlash > 12.0
    assert np.interp(87.0, q[::-1], tau[::-1]) - level < 0.05 * (peak - level)
    assert settled_after_deg(q, tau, level, 0.02 * peak) < 5.0


def test_reset_returns_to_the_straight_unloaded_state() -> None:
    plant = make_tendon_sheath_plant()
    first = run_sweep(plant, cycles=0.6)
    plant.reset()
    assert np.allclose(plant.step(DT_S, np.zeros(2)).tip_deg, 0.0)
    plant.reset()
    again = run_sweep(plant, cycles=0.6)
    assert np.array_equal(first.tip_deg, again.tip_deg)
    assert np.array_equal(first.torque_Nm, again.torque_Nm)


def test_identical_parameters_give_identical_runs() -> None:
    a = run_sweep(make_tendon_sheath_plant(coupling=1.0), cycles=0.6, other_deg=40.0)
    b = run_sweep(make_tendon_sheath_plant(coupling=1.0), cycles=0.6, other_deg=40.0)
    assert np.array_equal(a.tip_deg, b.tip_deg)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_two_knob_motion_keeps_tendons_pulling_and_the_tip_bounded(seed: int) -> None:
    """Arbitrary simultaneous motion (all effects on): tendons never push, nothing diverges."""
    rng = np.random.default_rng(seed)
    plant = make_tendon_sheath_plant(
        coupling=1.0, rate_dependence=0.5, tendon_compliance=0.3, sheath_curvature_deg=90.0
    )
    knots = rng.uniform(-90.0, 90.0, size=(12, 2))
    t_knots = np.cumsum(rng.uniform(0.5, 3.0, 12))
    t = np.arange(0.0, t_knots[-1], DT_S)
    targets = np.column_stack([np.interp(t, t_knots, knots[:, k]) for k in (0, 1)])
    q = np.zeros(2)
    max_step = 60.0 * DT_S  # the drives' speed limit, 60 deg/s
    for target in targets:
        q = q + np.clip(target - q, -max_step, max_step)
        qi = q
        step = plant.step(DT_S, qi)
        assert np.all(plant.tendon_tension_N() >= 0.0)
        assert np.all(np.abs(step.tip_deg) < 150.0)
        assert np.all(np.abs(step.knob_torque_Nm) < 2.0)


def test_bad_step_input_is_refused() -> None:
    plant = make_tendon_sheath_plant()
    with pytest.raises(ValueError, match="knob_deg"):
        plant.step(DT_S, np.array([np.nan, 0.0]))
    with pytest.raises(ValueError, match="dt_s"):
        plant.step(-1.0, np.zeros(2))


@pytest.mark.parametrize("params", [{}, {"coupling": 1.0}], ids=["default", "coupling"])
def test_fast_path_matches_the_full_solve(
    params: dict[str, Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Extending the last solution in closed form changes nothing but the speed."""
    fast = run_sweep(make_tendon_sheath_plant(**params), cycles=0.6, other_deg=50.0)
    monkeypatch.setattr(tendon_sheath._Knob, "_extend_fast", lambda *args: False)
    full = run_sweep(make_tendon_sheath_plant(**params), cycles=0.6, other_deg=50.0)
    assert np.allclose(fast.tip_deg, full.tip_deg, atol=1e-9)
    assert np.allclose(fast.torque_Nm, full.torque_Nm, atol=1e-12)


def test_quasi_static_results_do_not_depend_on_the_tick() -> None:
    def measure(dt_s: float) -> np.ndarray:
        plant = make_tendon_sheath_plant()
        t = np.arange(0.0, 37.5, dt_s)
        q = 90.0 * np.sin(2.0 * np.pi * 0.04 * t)
        tip = np.array([plant.step(dt_s, np.array([qi, 0.0])).tip_deg[0] for qi in q])
        return np.array(measure_dead_zone_backlash(q, tip))

    assert np.allclose(measure(0.002), measure(0.01), atol=0.5)
