"""The planetwist plant's laws: pure functions of one knob's constants (see ``params.py``).

Units: rope tension N, rope lengths and draws mm, torques N mm, angles rad.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from simrig.plants.planetwist.params import PlanetTwistKnob

SECTION_LENGTH_MM = 60.0
"""Rope between the section's base and the pull ring (part of the distal segment)."""


@dataclass(frozen=True)
class KnobConstants:
    """One knob's constants derived once (floats the step reads many times)."""

    ratio: float
    drum_mm: float
    play_rad: float
    mesh_Nmm_rad: float
    err2_rad: float
    err3_rad: float
    carrier_Nmm_rad: float
    bearing_Nmm: float
    efficiency: float
    proximal_mm_per_N: float
    distal_mm: float
    ea_N: float
    c_Nmm: float
    gj_Nmm2: float
    swivel0_Nmm: float
    swivel_arm_mm: float
    mu: float
    wrap_rad: float
    drag_N: float
    arm_mm: float
    bend_Nmm_rad: float
    stiffening: float
    takeup: float
    shaft_rad_per_N: float
    handle_Nm: float
    flow_Nmm: float


def knob_constants(knob: PlanetTwistKnob) -> KnobConstants:
    """The derived constants of ``knob`` (rope lengths split at the lumped contact)."""
    sheath_mm = 1000.0 * knob.sheath_length_m
    proximal_mm = 1000.0 * knob.free_length_m + knob.contact_fraction * sheath_mm
    distal_mm = (1.0 - knob.contact_fraction) * sheath_mm + SECTION_LENGTH_MM
    ea = knob.tendon_stiffness_N
    c = knob.twist_coupling_mm * ea
    gj = c * c / (knob.twist_share * ea) if knob.twist_share > 0.0 else math.inf
    e2, e3 = sorted((math.radians(knob.planet2_error_deg), math.radians(knob.planet3_error_deg)))
    return KnobConstants(
        ratio=knob.planet_ratio, drum_mm=knob.drum_radius_mm,
        play_rad=math.radians(knob.carrier_play_deg),
        mesh_Nmm_rad=knob.mesh_stiffness_Nmm_per_rad, err2_rad=e2, err3_rad=e3,
        carrier_Nmm_rad=knob.carrier_stiffness_Nmm_per_rad, bearing_Nmm=knob.drum_bearing_Nmm,
        efficiency=knob.gear_efficiency,
        proximal_mm_per_N=proximal_mm / ea, distal_mm=distal_mm, ea_N=ea, c_Nmm=c,
        gj_Nmm2=gj, swivel0_Nmm=knob.swivel_friction_Nmm, swivel_arm_mm=knob.swivel_arm_mm,
        mu=knob.sheath_friction, wrap_rad=math.radians(knob.sheath_wrap_deg),
        drag_N=knob.sheath_drag_N, arm_mm=knob.tendon_offset_mm,
        bend_Nmm_rad=knob.bend_stiffness_Nmm_per_rad, stiffening=knob.bend_stiffening_per_rad2,
        takeup=knob.cross_takeup, shaft_rad_per_N=math.radians(knob.shaft_bend_deg_per_N),
        handle_Nm=knob.handle_friction_Nm,
        flow_Nmm=knob.flow_moment_Nmm)


def gear_twist_rad(k: KnobConstants, torque_Nmm: float) -> tuple[float, float]:
    """Carrier wind-up under a carrier torque >= 0 and its compliance (rad, rad/(N mm)).

    The first planet takes the load alone until the second one's position error closes, then
    two share it, then all three (load sharing of a stage without a floating sun); the carrier
    twists in series.
    """
    km, e2, e3 = k.mesh_Nmm_rad, k.err2_rad, k.err3_rad
    t2 = km * e2
    t3 = km * (2.0 * e3 - e2)
    if torque_Nmm <= t2:
        mesh, slope = torque_Nmm / km, 1.0 / km
    elif torque_Nmm <= t3:
        mesh, slope = 0.5 * (torque_Nmm / km + e2), 0.5 / km
    else:
        mesh, slope = (torque_Nmm / km + e2 + e3) / 3.0, 1.0 / (3.0 * km)
    return mesh + torque_Nmm / k.carrier_Nmm_rad, slope + 1.0 / k.carrier_Nmm_rad


def proximal_give_mm(k: KnobConstants, tension_N: float) -> tuple[float, float]:
    """Drum draw taken by the proximal rope's stretch and the stage's wind-up at a proximal
    tension (mm), and its slope (mm/N)."""
    twist, slope = gear_twist_rad(k, k.drum_mm * tension_N)
    return (tension_N * k.proximal_mm_per_N + k.drum_mm * twist,
            k.proximal_mm_per_N + k.drum_mm * k.drum_mm * slope)


def proximal_tension_N(k: KnobConstants, give_mm: float) -> float:
    """Inverse of :func:`proximal_give_mm` (0 for a slack rope): piecewise linear, exact."""
    if give_mm <= 0.0:
        return 0.0
    km, r = k.mesh_Nmm_rad, k.drum_mm
    t2_N = km * k.err2_rad / r
    t3_N = km * (2.0 * k.err3_rad - k.err2_rad) / r
    h2_mm, slope1 = proximal_give_mm(k, t2_N)
    if give_mm <= h2_mm:
        return give_mm / slope1
    h3_mm, slope2 = proximal_give_mm(k, t3_N)
    if give_mm <= h3_mm:
        return t2_N + (give_mm - h2_mm) / slope2
    return t3_N + (give_mm - h3_mm) / proximal_give_mm(k, t3_N + 1.0)[1]


def strand_stretch(k: KnobConstants, tension_N: float, twist_rad_mm: float
                   ) -> tuple[float, float, float]:
    """Distal strand stretch (mm), its compliance (mm/N) and the swivel's new twist (rad/mm).

    T = EA e + C psi, M = C e + GJ psi (Costello's coupled strand); the swivel crimp holds psi
    until |M| reaches M0 + mu r T, then turns with M on that limit: a loading strand untwists
    and is softer than a releasing one (a knee and a loop in the rope's stretch).
    """
    ea, c, gj, length = k.ea_N, k.c_Nmm, k.gj_Nmm2, k.distal_mm
    if math.isinf(gj):
        return tension_N * length / ea, length / ea, twist_rad_mm
    strain = (tension_N - c * twist_rad_mm) / ea
    moment = c * strain + gj * twist_rad_mm
    limit = k.swivel0_Nmm + k.swivel_arm_mm * tension_N
    if -limit <= moment <= limit:
        return strain * length, length / ea, twist_rad_mm
    side = 1.0 if moment > 0.0 else -1.0
    ea_free = ea - c * c / gj
    strain = (tension_N - side * c * limit / gj) / ea_free
    twist = (side * limit - c * strain) / gj
    return (strain * length, length * (1.0 - side * c * k.swivel_arm_mm / gj) / ea_free, twist)


def section_moment_Nmm(k: KnobConstants, bend_rad: float, other_rad: float
                       ) -> tuple[float, float]:
    """The section's restoring moment and its slope: K = k b (1 + c (b^2 + b_other^2))."""
    c = k.stiffening
    base = 1.0 + c * (bend_rad * bend_rad + other_rad * other_rad)
    return (k.bend_Nmm_rad * bend_rad * base,
            k.bend_Nmm_rad * (base + 2.0 * c * bend_rad * bend_rad))


def flow_moment_Nmm(k: KnobConstants, t_s: float, bend_rad: float, heart_rate_hz: float
                    ) -> float:
    """Blood drag on the section (pushes toward +): quadratic in the pulsing flow speed
    (systolic 1.5x, diastolic 0.5x the mean), projected on the section's direction."""
    speed = 1.0 + 0.5 * math.sin(2.0 * math.pi * heart_rate_hz * t_s)
    return k.flow_Nmm * speed * speed / 1.125 * math.cos(bend_rad)


def contact_factor(k: KnobConstants, extra_wrap_rad: float) -> float:
    """m = mu x wrap / 2 of the lumped lumen contact (T_p - T_d = +-(m (T_p + T_d) + drag)),
    kept below 0.9 so a curved sheath does not lock it."""
    return min(0.9, 0.5 * k.mu * (k.wrap_rad + extra_wrap_rad))
