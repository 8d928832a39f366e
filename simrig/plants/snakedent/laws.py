"""The snakedent plant's laws: rolling-joint rope paths, the lumen contact, the detent.

Pure functions of floats (the plant calls them once or a few times per knob and step).

Rolling joint (two vertebra faces of radius R rolling without slip, each turning by phi = theta/2
about the moving contact point; the rope exits each face at a distance d from the axis and h
below the apex, c = R - h): the rope's length across one joint is
``l(theta) = 2 (R - d sin(phi) - c cos(phi))``. The pulling rope shortens by about d theta, but
both ropes lengthen by ``2 c (1 - cos phi)``: the pair's loop tightens as the joint bends, the
moment arm ``d cos(phi) - c sin(phi)`` falls with the bend, and a rope of the other plane (d = 0
in this joint's plane) is taken up by ``2 c (1 - cos phi)`` at every joint of this plane.
"""

from __future__ import annotations

import math


def rope_lengthening_mm(theta_rad: float, offset_mm: float, depth_mm: float) -> float:
    """Change of a rope's length across one rolling joint bent by ``theta_rad`` (negative:
    shorter); ``offset_mm`` is signed toward the bend (the pulling rope's is positive),
    ``depth_mm`` is c = R - h."""
    phi = 0.5 * theta_rad
    return 2.0 * (depth_mm * (1.0 - math.cos(phi)) - offset_mm * math.sin(phi))


def rope_arm_mm(theta_rad: float, offset_mm: float, depth_mm: float) -> float:
    """Moment arm of a rope's tension about one rolling joint: ``-d l / d theta``."""
    phi = 0.5 * theta_rad
    return offset_mm * math.cos(phi) - depth_mm * math.sin(phi)


def lumen_contact(u_mm: float, d_mm: float, z_mm: float, k_half_N_mm: float, ratio: float,
                  drag_N: float) -> tuple[float, float, float, float]:
    """One rope: a proximal and a distal half (stiffness ``k_half_N_mm`` each) joined at the
    lumen contact, which sticks at ``z_mm`` or slides when the tension across it exceeds the
    capacity: ``T_in <= ratio * T_out + drag`` in whichever direction it is drawn.

    ``u_mm`` is the drum's take-up beyond the slack, ``d_mm`` the rope the section has consumed.
    Answers (z, proximal tension, distal tension, distal stiffness d T_d / d(-d_mm)).
    """
    tp = k_half_N_mm * (u_mm - z_mm) if u_mm > z_mm else 0.0
    td = k_half_N_mm * (z_mm - d_mm) if z_mm > d_mm else 0.0
    if tp > ratio * td + drag_N:  # drawn in: the contact slides toward the drum
        z = (u_mm + ratio * d_mm - drag_N / k_half_N_mm) / (1.0 + ratio)
        if z <= d_mm:
            return u_mm - drag_N / k_half_N_mm, drag_N, 0.0, 0.0
        return z, k_half_N_mm * (u_mm - z), k_half_N_mm * (z - d_mm), (
            k_half_N_mm / (1.0 + ratio))
    if td > ratio * tp + drag_N:  # paid out: the section pulls the contact back
        z = (d_mm + ratio * u_mm + drag_N / k_half_N_mm) / (1.0 + ratio)
        if z >= u_mm:
            return d_mm + drag_N / k_half_N_mm, 0.0, drag_N, 0.0
        return z, k_half_N_mm * (u_mm - z), k_half_N_mm * (z - d_mm), (
            k_half_N_mm * ratio / (1.0 + ratio))
    return z_mm, tp, td, (k_half_N_mm if td > 0.0 else 0.0)


def detent_torque_Nm(knob_deg: float, peak_Nm: float, pitch_deg: float) -> float:
    """The spring ball on the indexing wheel: pushes the knob toward the nearest notch
    (conservative: no net work over a notch)."""
    return peak_Nm * math.sin(2.0 * math.pi * knob_deg / pitch_deg)
