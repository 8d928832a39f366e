"""Pure laws of the archwave plant: tensioner, coil-sheath band, strain-wave gear, motor.

Units: tendon lengths in mm, tensions in N, torques in N m, angles in rad unless named _deg.
"""

from __future__ import annotations

import math

SHEET_KT_NM_A = 0.0302
"""The data sheet's torque constant (the rig's default motor): used only to size the current
that warms the winding."""
SHEET_EFFICIENCY = 0.75


def tensioner_tension(e_mm: float, slack_mm: float, preload_N: float, rate_N_per_mm: float,
                      reserve_mm: float, stiff_N_per_mm: float) -> tuple[float, float]:
    """Tension (N) and its slope dT/de (N/mm) of a tendon drawn in by ``e_mm`` past its rest.

    A spring-loaded idler holds the tendon at ``preload + rate * e`` while it travels: up to
    ``slack_mm`` towards the drum (then it bottoms out and the stiff tendon carries the load:
    the dead zone has a soft floor, not zero load) and ``reserve_mm`` the other way (then it
    rests on its outer stop and the tendon goes slack).
    """
    if e_mm > slack_mm:
        return (preload_N + rate_N_per_mm * slack_mm + stiff_N_per_mm * (e_mm - slack_mm),
                stiff_N_per_mm)
    if e_mm >= -reserve_mm:
        return preload_N + rate_N_per_mm * e_mm, rate_N_per_mm
    t = preload_N - rate_N_per_mm * reserve_mm + stiff_N_per_mm * (e_mm + reserve_mm)
    return (t, stiff_N_per_mm) if t > 0.0 else (0.0, 0.0)


def path_slack_mm(lumen_deg: float, bends: tuple[tuple[float, float], ...],
                  clearance_mm: float, offset_mm: float) -> float:
    """Tendon length a bent shaft frees (mm, > 0: more slack) for a lumen at ``lumen_deg``.

    ``bends`` are (angle_deg, plane_deg) pairs. In a bend the tendon moves to the inside of its
    coil (its radial play) and the coil bundle, off the shaft's neutral axis, is shortened or
    lengthened by its offset times the bend, with the cosine of the angle between the lumen and
    the bend's plane.
    """
    total = 0.0
    for angle_deg, plane_deg in bends:
        a = math.radians(angle_deg)
        total += a * (clearance_mm + offset_mm * math.cos(math.radians(lumen_deg - plane_deg)))
    return total


def flex_z_after(z: float, d_delta: float, z_max: float) -> float:
    """Hysteretic twist of the flexspline after a twist increment (Bouc-Wen, n = 1, beta = gamma).

    Loading (the increment along z) saturates exponentially at ``z_max``; unloading is elastic
    until z changes sign. Integrated exactly over the increment.
    """
    if d_delta == 0.0:
        return z
    s = 1.0 if d_delta > 0.0 else -1.0
    if z * s < 0.0:  # unloading: linear until z crosses zero
        if abs(d_delta) <= abs(z):
            return z + d_delta
        d_delta += z  # the rest loads from zero
        z = 0.0
    left = abs(d_delta)
    return s * (z_max - (z_max - abs(z)) * math.exp(-left / z_max))


def flex_torque(delta: float, z: float, k0: float, k3: float, share: float) -> float:
    """Torque (N m) through the flexspline at twist ``delta`` (rad) and hysteretic twist z."""
    return share * k0 * delta + (1.0 - share) * k0 * z + k3 * delta * delta * delta


def flex_twist(target_Nm: float, delta: float, z: float, k0: float, k3: float, share: float,
               z_max: float) -> tuple[float, float]:
    """Twist and hysteretic state at which the flexspline carries ``target_Nm``, from (delta, z).

    Newton on the twist increment; z follows the increment exactly, so the loop of twist
    against torque is the gear's own hysteresis (load-dependent lost motion).
    """
    d = delta
    zn = z
    for _ in range(6):
        zn = flex_z_after(z, d - delta, z_max)
        f = flex_torque(d, zn, k0, k3, share) - target_Nm
        if abs(f) < 1e-12:
            break
        dz = 1.0 - abs(zn) / z_max if zn * (d - delta) > 0.0 else 1.0
        d -= f / (share * k0 + (1.0 - share) * k0 * dz + 3.0 * k3 * d * d)
    return d, flex_z_after(z, d - delta, z_max)


def kinematic_error_rad(output_rad: float, amplitude_deg: float, phase_deg: float) -> float:
    """Strain-wave transmission error: twice per output revolution (the wave's two lobes)."""
    return math.radians(amplitude_deg) * math.sin(2.0 * output_rad + math.radians(phase_deg))


def cogging_knob_Nm(output_rad: float, gear_ratio: float, peak_mNm: float,
                    per_rev: float) -> float:
    """The motor's cogging torque as the equivalent load on the knob (N m)."""
    return gear_ratio * 1e-3 * peak_mNm * math.sin(per_rev * gear_ratio * output_rad)


def winding_rise_K(rise_K: float, dt_s: float, power_W: float, r_th_K_per_W: float,
                   time_s: float) -> float:
    """Temperature rise of the motor above the handle's ambient after ``dt_s`` (one node)."""
    target = power_W * r_th_K_per_W
    return target + (rise_K - target) * math.exp(-dt_s / time_s)


def motor_current_A(knob_Nm: float, gear_ratio: float) -> float:
    """The current a knob torque asks of the motor (data-sheet constants: for heating only)."""
    return abs(knob_Nm) / (gear_ratio * SHEET_KT_NM_A * SHEET_EFFICIENCY)
