"""Closed-form laws of the wormeyelet plant: rope over one lumen contact, the eyelet band of the
spacer-disk section, the worm's power-flow efficiency and the shear-thinning damper.

Units: tension N, lengths mm, angles rad, torque N m.
"""

from __future__ import annotations

import math
from typing import NamedTuple


class RopeState(NamedTuple):
    """A rope's answer for one bend: proximal and distal tension, d(distal)/d(bend), and where
    the rope now sits at the lumen contact (mm of draw-in)."""

    proximal_N: float
    distal_N: float
    d_distal_N_per_rad: float
    contact_mm: float


def rope(draw_mm: float, demand_mm: float, side: float, arm_mm: float, contact_mm: float,
         c_prox: float, c_dist: float, ratio: float, drag_N: float) -> RopeState:
    """One rope: draw-in ``draw_mm`` at the drum (slack already taken off), the section's path
    demand ``demand_mm`` (= side * arm * bend), a lumen contact that sticks while the proximal
    tension lies within [(T_d - drag)/ratio, ratio*T_d + drag] (capstan ratio e^{mu psi}) and
    otherwise slides. ``contact_mm`` is the rope's place at the contact from the last step.
    A rope carries no compression: each piece is slack below zero stretch."""
    t_p = max(0.0, (draw_mm - contact_mm) / c_prox)
    t_d = max(0.0, (contact_mm - demand_mm) / c_dist)
    if t_p > ratio * t_d + drag_N:  # pulled through the contact
        t_d = (draw_mm - demand_mm - c_prox * drag_N) / (c_prox * ratio + c_dist)
        if t_d <= 0.0:
            t_p = max(0.0, (draw_mm - demand_mm) / c_prox)
            return RopeState(t_p, 0.0, 0.0, demand_mm)
        return RopeState(ratio * t_d + drag_N, t_d, -side * arm_mm / (c_prox * ratio + c_dist),
                         demand_mm + c_dist * t_d)
    if t_p < (t_d - drag_N) / ratio:  # the section pulls the rope back through the contact
        t_d_slide = (draw_mm - demand_mm + c_prox * drag_N / ratio) / (c_prox / ratio + c_dist)
        if t_d_slide > drag_N:
            return RopeState((t_d_slide - drag_N) / ratio, t_d_slide,
                             -side * arm_mm / (c_prox / ratio + c_dist),
                             demand_mm + c_dist * t_d_slide)
        # proximal piece slack: the contact's drag alone holds the distal piece
        return RopeState(0.0, drag_N, 0.0, demand_mm + c_dist * drag_N)
    slope = -side * arm_mm / c_dist if t_d > 0.0 else 0.0
    return RopeState(t_p, t_d, slope, contact_mm)


def eyelet_band(bend_rad: float, stiffness_N_per_rad: float, friction: float,
                cross_rad: float, disk_N: float = 0.0) -> tuple[float, float, float, float]:
    """Net distal tension the spacer-disk section holds at ``bend_rad``: (low, high, dlow, dhigh).

    A rope sliding through the eyelets of a bending backbone loses tension with the wrap it has
    passed, the wrap being the bend itself, so its curvature falls along the section: with
    a = K/mu, loading needs T = a (e^{mu theta} - 1), releasing lets it go at
    T = a (1 - e^{-mu theta}). The other plane's bend ``cross_rad`` adds wrap along the whole
    section (factor e^{+-mu cross}). The spacer disks rubbing the cover sleeve add a constant
    ``disk_N`` either way. Between the two edges the section sticks (the tip holds)."""
    a = stiffness_N_per_rad / friction
    grow = math.exp(friction * cross_rad)
    e = math.exp(friction * bend_rad)
    if bend_rad >= 0.0:
        hi, dhi = a * grow * (e - 1.0), stiffness_N_per_rad * grow * e
        lo, dlo = a / grow * (1.0 - 1.0 / e), stiffness_N_per_rad / grow / e
    else:
        hi, dhi = -a / grow * (1.0 - e), stiffness_N_per_rad / grow * e
        lo, dlo = -a * grow * (1.0 / e - 1.0), stiffness_N_per_rad * grow / e
    return lo - disk_N, hi + disk_N, dlo, dhi


def worm_knob_torque(drum_Nm: float, driving: bool, ratio: float, eta_drive: float,
                     eta_back: float) -> float:
    """Knob torque for a drum load: the worm pushes the load (power knob -> drum) at the driving
    efficiency, the load pushes the worm (power drum -> knob) at the back-driving one."""
    return drum_Nm / (ratio * eta_drive) if driving else drum_Nm * eta_back / ratio


def damper_torque(speed_rad_s: float, viscous_Nm_s: float, thinning_rad_s: float) -> float:
    """Silicone oil between rotor and housing: Newtonian at low speed, shear-thinning above
    ``thinning_rad_s`` (Cross law with exponent 1: the viscosity halves there)."""
    return viscous_Nm_s * speed_rad_s / (1.0 + abs(speed_rad_s) / thinning_rad_s)
