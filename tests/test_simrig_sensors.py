"""Current-sensor dynamics and the simulated EM tracker."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from simrig.current_sensor import CurrentSensor
from simrig.tracker import EmTracker

DT_S = 0.004


def readings(sensor: CurrentSensor, true_A: np.ndarray) -> np.ndarray:
    return np.array([sensor.measure(DT_S, float(x)) for x in true_A])


def test_ideal_sensor_reads_the_true_current() -> None:
    true = np.sin(np.linspace(0.0, 10.0, 500)) * 0.15
    assert np.array_equal(readings(CurrentSensor(), true), true)


def test_lag_delays_a_step_by_its_time_constant() -> None:
    lag_s = 0.048
    out = readings(CurrentSensor(lag_s=lag_s), np.r_[np.zeros(10), np.ones(200)])
    k = 12  # ticks in one time constant
    assert out[10 + k - 1] == pytest.approx(1.0 - np.exp(-1.0), abs=0.01)
    assert out[-1] == pytest.approx(1.0, abs=1e-3)


def test_lag_delays_the_current_signature_of_a_sweep() -> None:
    t = np.arange(0.0, 5.0, DT_S)
    true = np.sin(2.0 * np.pi * 0.5 * t)
    out = readings(CurrentSensor(lag_s=0.1), true)
    lags = np.arange(0, 60)
    err = [np.sum((out[200 + s :] - true[200 : true.size - s]) ** 2) for s in lags]
    assert int(lags[np.argmin(err)]) * DT_S == pytest.approx(0.1, abs=0.02)


def test_offset_and_gain_are_applied() -> None:
    out = readings(CurrentSensor(offset_A=0.01, gain=1.1), np.full(5, 0.1))
    assert np.allclose(out, 1.1 * 0.1 + 0.01)


def test_noise_has_the_configured_spread() -> None:
    out = readings(CurrentSensor(noise_A=0.005, seed=3), np.zeros(20000))
    assert np.std(out) == pytest.approx(0.005, rel=0.05)
    assert abs(np.mean(out)) < 3e-4


def test_spikes_occur_at_the_configured_rate() -> None:
    n = 50000
    out = readings(CurrentSensor(spike_rate_hz=2.0, spike_A=0.05, seed=1), np.zeros(n))
    spikes = np.count_nonzero(np.abs(out) > 0.04)
    expected = 2.0 * n * DT_S
    assert abs(spikes - expected) < 4.0 * np.sqrt(expected)


def test_sensor_is_deterministic_per_seed_and_resets() -> None:
    def make() -> CurrentSensor:
        return CurrentSensor(lag_s=0.01, noise_A=0.003, spike_rate_hz=1.0, seed=7)

    true = np.linspace(-0.1, 0.1, 3000)
    a, b = make(), make()
    first = readings(a, true)
    assert np.array_equal(first, readings(b, true))
    a.reset()
    assert np.array_equal(first, readings(a, true))
    assert not np.array_equal(first, readings(CurrentSensor(0.01, 0.0, 0.003, 1.0, seed=8), true))


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"lag_s": -1.0}, "lag_s"),
        ({"noise_A": float("nan")}, "noise_A"),
        ({"spike_rate_hz": -0.1}, "spike_rate_hz"),
        ({"offset_A": float("inf")}, "offset_A"),
        ({"gain": 0.0}, "gain"),
    ],
)
def test_sensor_refuses_bad_parameters(kwargs: dict[str, Any], name: str) -> None:
    with pytest.raises(ValueError, match=name):
        CurrentSensor(**kwargs)


def test_tracker_adds_noise_of_the_configured_spread() -> None:
    tracker = EmTracker(noise_deg=0.1, seed=0)
    out = np.array([tracker.measure(np.array([10.0, -5.0])) for _ in range(5000)])
    assert out.shape == (5000, 2)
    assert np.std(out - [10.0, -5.0]) == pytest.approx(0.1, rel=0.05)


def test_tracker_is_deterministic_per_seed() -> None:
    a, b = EmTracker(0.1, seed=4), EmTracker(0.1, seed=4)
    assert np.array_equal(a.measure(np.zeros(2)), b.measure(np.zeros(2)))


def test_noiseless_tracker_is_exact() -> None:
    assert np.array_equal(EmTracker(noise_deg=0.0).measure(np.array([1.5, 2.5])), [1.5, 2.5])


def test_tracker_refuses_negative_noise() -> None:
    with pytest.raises(ValueError, match="noise_deg"):
        EmTracker(noise_deg=-0.1)


def test_tracker_block_draws_equal_per_tick_draws_across_block_edges() -> None:
    tracker = EmTracker(noise_deg=0.3, seed=11)
    rng = np.random.default_rng(11)
    tip = np.array([5.0, -2.0])
    for _ in range(EmTracker.block):  # two values per tick: crosses a block edge mid-run
        expected = tip + 0.3 * rng.standard_normal(tip.shape)
        assert np.array_equal(tracker.measure(tip), expected)


def test_tracker_reset_restarts_the_noise_sequence() -> None:
    tracker = EmTracker(noise_deg=0.3, seed=11)
    first = [tracker.measure(np.zeros(2)) for _ in range(3)]
    tracker.reset()
    again = [tracker.measure(np.zeros(2)) for _ in range(3)]
    assert all(np.array_equal(a, b) for a, b in zip(first, again, strict=True))


def test_tracker_pair_draws_the_same_noise_as_measure_across_block_edges() -> None:
    by_array = EmTracker(noise_deg=0.3, seed=5)
    by_pair = EmTracker(noise_deg=0.3, seed=5)
    for k in range(EmTracker.block + 3):  # crosses a block edge
        tip = (0.01 * k, -0.02 * k)
        assert list(by_pair.measure_pair(*tip)) == by_array.measure(np.array(tip)).tolist()


def test_tracker_pair_and_measure_share_one_noise_sequence() -> None:
    mixed = EmTracker(noise_deg=0.3, seed=5)
    arrays = EmTracker(noise_deg=0.3, seed=5)
    got = [mixed.measure_pair(1.0, 2.0), tuple(mixed.measure(np.array([1.0, 2.0])))]
    want = [tuple(arrays.measure(np.array([1.0, 2.0]))) for _ in range(2)]
    assert got == want


def test_sensor_lag_follows_a_change_of_period() -> None:
    lag_s = 0.01
    sensor = CurrentSensor(lag_s=lag_s)
    sensor.measure(0.004, 0.0)
    first = sensor.measure(0.004, 1.0)
    second = sensor.measure(0.002, 1.0)
    assert first == 1.0 - np.exp(-0.004 / lag_s)
    assert second == pytest.approx(first + (1.0 - np.exp(-0.002 / lag_s)) * (1.0 - first),
                                   rel=1e-15)


def test_sensor_refuses_a_negative_period_after_a_valid_one() -> None:
    sensor = CurrentSensor(lag_s=0.01)
    sensor.measure(0.004, 0.0)
    with pytest.raises(ValueError, match="dt_s"):
        sensor.measure(-0.004, 0.0)
