"""The simulated knob motor: tracking bandwidth, speed and current limits, current equation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from simrig.motor import Motor, MotorParams

DT_S = 0.004
GEAR = 50.0


def track(motor: Motor, target_deg: np.ndarray, load_Nm: float = 0.0) -> np.ndarray:
    out = np.empty_like(target_deg)
    for k, r in enumerate(target_deg):
        out[k] = motor.step(float(r), powered=True)
        motor.set_load(load_Nm, powered=True)
    return out


def sine_error(freq_hz: float) -> float:
    motor = Motor(MotorParams(), GEAR, DT_S)
    t = np.arange(int(4 / freq_hz / DT_S)) * DT_S
    r = 5.0 * np.sin(2 * np.pi * freq_hz * t)
    x = track(motor, r)
    half = len(t) // 2
    return float(np.max(np.abs(x[half:] - r[half:])))


def test_slow_targets_are_tracked_closely():
    assert sine_error(0.5) < 0.01 * 5.0


def test_bandwidth_limits_fast_targets():
    assert sine_error(20.0) > 20 * sine_error(0.5)


def test_speed_limit_bounds_the_knob_velocity():
    params = MotorParams(max_speed_rpm=3000.0)
    motor = Motor(params, GEAR, DT_S)
    x = track(motor, np.full(200, 90.0))
    v_max_deg_s = params.max_speed_rpm * 6.0 / GEAR
    assert np.max(np.diff(x)) / DT_S <= v_max_deg_s * 1.001
    assert x[-1] == pytest.approx(90.0, abs=1e-3)


def test_holding_current_is_the_geared_load_over_torque_constant():
    params = MotorParams()
    motor = Motor(params, GEAR, DT_S)
    track(motor, np.zeros(100), load_Nm=0.1)
    expected = 0.1 / (GEAR * params.gear_efficiency) / params.torque_constant_Nm_A
    assert motor.current_A == pytest.approx(expected, rel=1e-6)


def test_back_driven_load_needs_less_current_than_driving_it():
    params = MotorParams(friction_Nm=0.0, viscous_Nm_s_rad=0.0)
    ramp = np.linspace(0.0, 20.0, 400)
    driving = Motor(params, GEAR, DT_S)
    track(driving, ramp, load_Nm=0.1)  # load resists the motion
    back = Motor(params, GEAR, DT_S)
    track(back, ramp, load_Nm=-0.1)  # load pulls along the motion
    eta = params.gear_efficiency
    assert abs(back.current_A) == pytest.approx(abs(driving.current_A) * eta * eta, rel=0.05)


def test_current_limit_saturates_and_the_motor_falls_behind():
    params = MotorParams(max_current_A=0.5)
    motor = Motor(params, GEAR, DT_S)
    stall_Nm = params.torque_constant_Nm_A * params.max_current_A * GEAR * params.gear_efficiency
    x = track(motor, np.linspace(0.0, 30.0, 300), load_Nm=1.5 * stall_Nm)
    assert motor.current_A == pytest.approx(params.max_current_A)
    assert x[-1] < 25.0


def test_unpowered_motor_holds_position_without_current():
    motor = Motor(MotorParams(), GEAR, DT_S, position_deg=12.0)
    for _ in range(10):
        assert motor.step(40.0, powered=False) == 12.0
        assert motor.set_load(0.2, powered=False) == 0.0


def test_jammed_motor_does_not_move_and_draws_the_current_limit():
    params = MotorParams()
    motor = Motor(params, GEAR, DT_S)
    motor.jammed = True
    x = track(motor, np.linspace(0.0, 10.0, 50))
    assert np.all(x == 0.0)
    assert motor.current_A == pytest.approx(params.max_current_A)


@pytest.mark.parametrize("name", ["torque_constant_Nm_A", "rotor_inertia_kgm2", "bandwidth_hz"])
def test_parameters_must_be_positive(name):
    with pytest.raises(ValueError, match=name):
        MotorParams(**{name: 0.0})


def test_efficiency_must_be_a_fraction():
    with pytest.raises(ValueError, match="gear_efficiency"):
        MotorParams(gear_efficiency=1.5)
    assert math.isclose(MotorParams().gear_efficiency, 0.75)
