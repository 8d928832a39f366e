"""A handle's torque ripple period read from the current (tsmd.calibration.ripple_period)."""

from __future__ import annotations

import math

import numpy as np

from tsmd.calibration.ripple_period import (
    RippleRead,
    candidate_period,
    handle_period,
    phase_randomised,
    ramp_residuals,
    sweep_ripple,
)
from tsmd.calibration.signal import Conditioned, condition

PERIOD_DEG = 15.0
EDGE_DEG = 22.0


def _sweep(ripple_A: float, seed: int = 0) -> Conditioned:
    """Three cycles of +-90 deg at 0.06 Hz: a dead zone of +-``EDGE_DEG``, a loaded ramp of
    2 mA/deg beyond it on each side (its sign the direction's), a backlash-free release, and a
    ripple of ``PERIOD_DEG`` locked to the knob angle, 3 mA of noise."""
    t = np.arange(0.0, 50.0, 0.004)
    q = 90.0 * np.sin(2.0 * np.pi * 0.06 * t)
    direction = np.sign(np.gradient(q))
    load = 0.002 * np.maximum(direction * q - EDGE_DEG, 0.0)
    ripple = ripple_A * np.sin(2.0 * np.pi * q / PERIOD_DEG)
    noise = np.random.default_rng(seed).normal(0.0, 0.003, t.size)
    return condition(t, q, q, direction * (0.02 + load) + ripple + noise)


def test_the_autocorrelation_proposes_the_period_of_a_ripple_locked_to_the_knob() -> None:
    ramps = ramp_residuals(_sweep(0.004))
    period, _ = candidate_period([r for d in (1, -1) for _, r in ramps[d]])
    assert abs(period - PERIOD_DEG) < 1.0


def test_a_ramp_without_a_ripple_repeats_far_less_than_one_with() -> None:
    rippled = sweep_ripple(_sweep(0.004))
    plain = sweep_ripple(_sweep(0.0))
    assert rippled.autocorrelation > 3.0 * max(plain.autocorrelation, 0.05)


def test_the_two_directions_of_a_locked_ripple_match_at_whole_periods() -> None:
    read = sweep_ripple(_sweep(0.004))
    assert read.lock > 0.5


def test_phase_randomising_keeps_the_amplitude_spectrum() -> None:
    x = np.random.default_rng(3).normal(size=200)
    y = phase_randomised(x, np.random.default_rng(4))
    assert np.allclose(np.abs(np.fft.rfft(y)), np.abs(np.fft.rfft(x - x.mean())))


def _read(period_deg: float, p_value: float) -> RippleRead:
    return RippleRead(period_deg, 0.7, period_deg, 0.8, p_value, 6)


def test_the_handle_period_needs_every_sweep_locked() -> None:
    assert handle_period([_read(15.0, 0.005), _read(15.2, 0.5)]) is None


def test_the_handle_period_needs_the_sweeps_to_agree() -> None:
    assert handle_period([_read(15.0, 0.005), _read(24.0, 0.005)]) is None


def test_sweeps_locked_at_one_period_give_it_on_the_grid() -> None:
    period = handle_period([_read(14.9, 0.005), _read(15.2, 0.005)])
    assert period is not None and math.isclose(period, 15.0)
