"""A servo motor behind a gearbox, tracking an interpolated CSP target.

The drive's position loop is modelled as a critically damped second-order tracker of the
linearly interpolated target (velocity feed-forward included), discretised exactly per period,
then bounded by the velocity limit and by the torque the current limit allows. Current follows
from the torque balance at the motor shaft: inertia, friction and the knob load through the gear.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class MotorParams:
    """Data-sheet constants of the knob motor and gearbox (defaults: a small 24 V BLDC)."""

    torque_constant_Nm_A: float = 0.0302
    rotor_inertia_kgm2: float = 4.1e-7
    """Rotor plus gearbox input inertia."""
    friction_Nm: float = 0.6e-3
    """Coulomb friction at the motor shaft."""
    viscous_Nm_s_rad: float = 1.5e-6
    friction_speed_rad_s: float = 0.5
    """Speed over which Coulomb friction builds up (tanh smoothing; keeps it deterministic)."""
    gear_efficiency: float = 0.75
    bandwidth_hz: float = 30.0
    """Closed-loop position bandwidth of the drive."""
    max_current_A: float = 3.0
    max_speed_rpm: float = 8000.0

    def __post_init__(self) -> None:
        for name in ("torque_constant_Nm_A", "rotor_inertia_kgm2", "bandwidth_hz",
                     "max_current_A", "max_speed_rpm"):
            if not getattr(self, name) > 0:
                raise ValueError(f"motor parameter {name} must be > 0")
        if not 0 < self.gear_efficiency <= 1:
            raise ValueError("motor parameter gear_efficiency must be in (0, 1]")


class Motor:
    """One knob motor. State in knob degrees; call :meth:`step` once per period."""

    def __init__(self, params: MotorParams, gear_ratio: float, dt_s: float,
                 position_deg: float = 0.0) -> None:
        self.params = params
        self.gear_ratio = gear_ratio
        self.dt_s = dt_s
        self.position_deg = position_deg
        self.velocity_deg_s = 0.0
        self.current_A = 0.0
        self.jammed = False
        self.travel_deg = (-math.inf, math.inf)
        """Hard stops of the knob mechanism (knob degrees); none by default."""
        self._pressing_Nm = 0.0
        self._reference_deg = position_deg
        self._load_Nm = 0.0
        self._accel_rad_s2 = 0.0
        self._saturated_Nm = 0.0
        self._rad_per_knob_deg = gear_ratio * math.pi / 180.0
        self._max_velocity_deg_s = params.max_speed_rpm * 6.0 / gear_ratio
        w = 2.0 * math.pi * params.bandwidth_hz
        self._stiffness_Nm_rad = params.rotor_inertia_kgm2 * w * w
        """Static stiffness of the position loop (what pushes against a hard stop)."""
        e = math.exp(-w * dt_s)
        # exact transition of e'' = -w^2 e - 2 w e' (critically damped) over dt
        self._phi = ((1.0 + w * dt_s) * e, dt_s * e, -w * w * dt_s * e, (1.0 - w * dt_s) * e)

    def limit_speed(self, max_speed_rpm: float) -> None:
        """Apply the drive's max motor speed (0x6080), never above the motor's own rating."""
        rpm = min(max_speed_rpm, self.params.max_speed_rpm) if max_speed_rpm > 0 else (
            self.params.max_speed_rpm)
        self._max_velocity_deg_s = rpm * 6.0 / self.gear_ratio

    def hold(self) -> None:
        """Make the current position the reference (entering OPERATION ENABLED)."""
        self._reference_deg = self.position_deg
        self.velocity_deg_s = 0.0

    def step(self, target_deg: float, powered: bool) -> float:
        """Advance one period towards ``target_deg``; return the new knob position."""
        dt = self.dt_s
        x0 = self.position_deg
        v0 = self.velocity_deg_s
        if not powered or self.jammed:
            self.velocity_deg_s = 0.0
            self._accel_rad_s2 = 0.0
            self._saturated_Nm = 0.0
            self._reference_deg = target_deg if powered else x0
            return x0
        r0 = self._reference_deg
        vr = (target_deg - r0) / dt
        e = x0 - r0
        ed = v0 - vr
        p = self._phi
        e1 = p[0] * e + p[1] * ed
        ed1 = p[2] * e + p[3] * ed
        x1 = target_deg + e1
        v1 = vr + ed1
        vmax = self._max_velocity_deg_s
        if v1 > vmax or v1 < -vmax:
            v1 = vmax if v1 > 0 else -vmax
            x1 = x0 + 0.5 * (v0 + v1) * dt
        # torque the current limit leaves for acceleration
        par = self.params
        k = self._rad_per_knob_deg
        accel = (v1 - v0) / dt * k
        load = self._load_torque_motor_Nm(self._load_Nm, v1)
        drag = self._drag_Nm(v1 * k)
        torque_max = par.torque_constant_Nm_A * par.max_current_A
        needed = par.rotor_inertia_kgm2 * accel + drag + load
        self._saturated_Nm = 0.0
        if needed > torque_max or needed < -torque_max:
            limit = torque_max if needed > 0 else -torque_max
            accel = (limit - drag - load) / par.rotor_inertia_kgm2
            v1 = v0 + accel / k * dt
            x1 = x0 + 0.5 * (v0 + v1) * dt
            self._saturated_Nm = limit  # the drive delivers its peak current this period
        lo, hi = self.travel_deg
        self._pressing_Nm = 0.0
        if x1 < lo or x1 > hi:  # against a hard stop: the loop pushes as far as the target is
            x1 = lo if x1 < lo else hi
            v1 = 0.0
            accel = 0.0
            push = self._stiffness_Nm_rad * (target_deg - x1) * k
            self._pressing_Nm = max(-torque_max, min(torque_max, push))
        self.position_deg = x1
        self.velocity_deg_s = v1
        self._reference_deg = target_deg
        self._accel_rad_s2 = accel
        return x1

    def set_load(self, knob_torque_Nm: float, powered: bool) -> float:
        """Record the plant's knob torque and return the true motor current (A)."""
        self._load_Nm = knob_torque_Nm
        if not powered:
            self.current_A = 0.0
            return 0.0
        par = self.params
        k = self._rad_per_knob_deg
        v = self.velocity_deg_s
        if self.jammed:
            torque = par.torque_constant_Nm_A * par.max_current_A * (
                1.0 if self._reference_deg >= self.position_deg else -1.0)
        elif self._pressing_Nm:
            torque = self._pressing_Nm + self._load_torque_motor_Nm(knob_torque_Nm, 0.0)
        elif self._saturated_Nm:
            torque = self._saturated_Nm
        else:
            torque = (par.rotor_inertia_kgm2 * self._accel_rad_s2 + self._drag_Nm(v * k)
                      + self._load_torque_motor_Nm(knob_torque_Nm, v))
        current = torque / par.torque_constant_Nm_A
        imax = par.max_current_A
        self.current_A = imax if current > imax else -imax if current < -imax else current
        return self.current_A

    def _drag_Nm(self, speed_rad_s: float) -> float:
        par = self.params
        return (par.friction_Nm * math.tanh(speed_rad_s / par.friction_speed_rad_s)
                + par.viscous_Nm_s_rad * speed_rad_s)

    def _load_torque_motor_Nm(self, knob_torque_Nm: float, velocity_deg_s: float) -> float:
        """Knob load seen at the motor: losses add when driving, subtract when back-driven."""
        eta = self.params.gear_efficiency
        n = self.gear_ratio
        if knob_torque_Nm * velocity_deg_s >= 0.0:
            return knob_torque_Nm / (n * eta)
        return knob_torque_Nm * eta / n
