"""The built-in tendon-sheath plant shows the paper's signatures on a +-90 deg, 0.04 Hz sweep."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from drivers.plant import tendon_sheath
from drivers.plant.analysis import loaded_slope, measure_dead_zone_backlash
from drivers.plant.base import Plant, load_plant
from drivers.plant.report import SweepRecord
from drivers.plant.report import run_sweep as report_sweep
from drivers.plant.tendon_sheath import TendonSheathPlant, make_tendon_sheath_plant

DT_S = 0.004  # 250 Hz ticks


def run_sweep(plant: Plant, knob: int = 0, **kwargs: Any) -> SweepRecord:
    """The report's sweep at 250 Hz ticks (it resets the plant first)."""
    return report_sweep(plant, knob, dt_s=DT_S, **kwargs)


@pytest.fixture(scope="module", params=[0, 1], ids=["phi1", "phi2"])
def default_sweep(request: pytest.FixtureRequest) -> SweepRecord:
    return run_sweep(make_tendon_sheath_plant(), knob=request.param)


def test_factory_builds_a_plant_through_the_config_loader() -> None:
    plant = load_plant("drivers.plant.tendon_sheath:make_tendon_sheath_plant", {"coupling": 1.0})
    assert isinstance(plant, TendonSheathPlant)
    assert isinstance(plant, Plant)


def test_straight_and_unloaded_at_rest() -> None:
    step = make_tendon_sheath_plant().step(DT_S, np.zeros(2))
    assert np.allclose(step.tip_deg, 0.0)
    assert np.allclose(step.knob_torque_Nm, 0.0)


def test_sweep_shows_a_dead_zone_on_both_sides(default_sweep: SweepRecord) -> None:
    m = measure_dead_zone_backlash(default_sweep.knob_deg, default_sweep.tip_deg)
    assert 15.0 <= m.dead_zone_pos_deg <= 25.0
    assert -25.0 <= m.dead_zone_neg_deg <= -15.0


def test_sweep_shows_backlash_after_both_reversals(default_sweep: SweepRecord) -> None:
    m = measure_dead_zone_backlash(default_sweep.knob_deg, default_sweep.tip_deg)
    assert 15.0 <= m.backlash_pos_deg <= 25.0
    assert 15.0 <= m.backlash_neg_deg <= 25.0


def test_tip_slope_in_the_loaded_region_is_about_1_3(default_sweep: SweepRecord) -> None:
    pos, neg = loaded_slope(default_sweep.knob_deg, default_sweep.tip_deg, 40.0, 85.0)
    assert 1.2 <= pos <= 1.45
    assert 1.2 <= neg <= 1.45


def test_backlash_transitions_are_curved_not_straight(default_sweep: SweepRecord) -> None:
    """After the backlash the tip speeds up over several degrees instead of snapping to a line."""
    s = default_sweep
    falling = (s.t_s > 31.25) & (s.t_s < 37.5) & (s.knob_deg > 30.0)
    q, y = s.knob_deg[falling], s.tip_deg[falling]
    start = np.flatnonzero(y < y[0] - 0.05)[0]
    early = (y[start] - np.interp(q[start] - 2.0, q[::-1], y[::-1])) / 2.0
    later = (
        np.interp(q[start] - 12.0, q[::-1], y[::-1]) - np.interp(q[start] - 17.0, q[::-1], y[::-1])
    ) / 5.0
    assert early < 0.7 * later


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


def test_knob_torque_is_of_order_0_05_to_0_3_Nm(default_sweep: SweepRecord) -> None:
    assert 0.05 <= np.max(np.abs(default_sweep.torque_Nm)) <= 0.3


def test_torque_changes_sign_after_a_reversal_and_stays_near_zero_while_released(
    default_sweep: SweepRecord,
) -> None:
    s = default_sweep
    peak = np.max(s.torque_Nm)
    m = measure_dead_zone_backlash(s.knob_deg, s.tip_deg)
    i_rev = int(np.argmax(s.knob_deg[: int(25.0 / DT_S)]))
    after = slice(i_rev, i_rev + int(12.0 / DT_S))
    q, tau = s.knob_deg[after], s.torque_Nm[after]
    released = (q < 90.0 - m.backlash_pos_deg - 2.0) & (q > m.dead_zone_pos_deg + 5.0)
    assert tau[0] > 0.8 * peak
    assert np.all(tau[q < 87.0] < 0.0)  # sharp: the sign has changed within 3 deg
    assert np.max(np.abs(tau[released])) < 0.1 * peak


def test_torque_makes_a_small_peak_after_reversal_then_settles(default_sweep: SweepRecord) -> None:
    s = default_sweep
    i_rev = int(np.argmax(s.knob_deg[: int(25.0 / DT_S)]))
    window = slice(i_rev, i_rev + int(8.0 / DT_S))
    released = s.knob_deg[window] > 30.0  # before the other tendon engages
    q, tau = s.knob_deg[window][released], s.torque_Nm[window][released]
    i_peak = int(np.argmin(tau))
    settled = float(np.median(tau[(q < q[i_peak] - 5.0) & (q > q[i_peak] - 15.0)]))
    assert 90.0 - q[i_peak] < 6.0  # right after the reversal
    assert tau[i_peak] < settled - 0.1 * abs(settled)  # a peak ...
    assert tau[i_peak] - settled > -0.05 * np.max(s.torque_Nm)  # ... and a small one


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
        assert np.all(np.abs(step.knob_torque_Nm) < 1.0)


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
