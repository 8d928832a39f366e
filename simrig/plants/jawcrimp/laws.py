"""The jawcrimp plant's laws: pure functions of their arguments (units in the names)."""

from __future__ import annotations

import math


def jaw_torque_Nmm(twist_rad: float, play_rad: float, play_stiffness_Nmm: float,
                   scale_rad: float, scale_Nmm: float) -> tuple[float, float]:
    """Torque an elastomer jaw coupling passes at ``twist_rad`` (knob side minus drum side),
    and its stiffness (N mm/rad).

    Inside the play only the set spider's weak residual stiffness; past it the spider's lobes
    are squeezed and the stiffness rises steeply (exponentially) with the squeeze:
    torque = scale * sinh((|twist| - play) / scale_rad), the inverse of an asinh twist law.
    """
    excess = abs(twist_rad) - play_rad
    torque = play_stiffness_Nmm * twist_rad
    stiffness = play_stiffness_Nmm
    if excess > 0.0:
        z = excess / scale_rad
        sign = 1.0 if twist_rad > 0.0 else -1.0
        torque += sign * scale_Nmm * math.sinh(z)
        stiffness += scale_Nmm / scale_rad * math.cosh(z)
    return torque, stiffness


NodeAnswer = tuple[float, float, float, float, float, float, float]
"""(T1, T2, x, dT1/du, dT1/dy, dT2/du, dT2/dy): tensions (N), node position (mm), slopes."""


def friction_node(u_mm: float, y_mm: float, x0_mm: float, k1_N_per_mm: float,
                  k2_N_per_mm: float, share: float, drag_N: float) -> NodeAnswer:
    """One rope over a lumped friction node: drum end ``u`` (draw-in less slack), tip end ``y``.

    The proximal part (stiffness ``k1``) and the distal part (``k2``) are taut only when
    stretched. The node holds where it was (``x0``) while the tension step across it stays
    within drag + share (T1 + T2); past that it slides with the step at that capacity.
    """
    e1 = u_mm - x0_mm
    e2 = x0_mm - y_mm
    t1 = k1_N_per_mm * e1 if e1 > 0.0 else 0.0
    t2 = k2_N_per_mm * e2 if e2 > 0.0 else 0.0
    diff = t1 - t2
    if abs(diff) <= drag_N + share * (t1 + t2):
        return (t1, t2, x0_mm, k1_N_per_mm if e1 > 0.0 else 0.0, 0.0, 0.0,
                -k2_N_per_mm if e2 > 0.0 else 0.0)
    sign = 1.0 if diff > 0.0 else -1.0
    a1 = k1_N_per_mm * (1.0 - sign * share)
    a2 = k2_N_per_mm * (1.0 + sign * share)
    x = (a1 * u_mm + a2 * y_mm - sign * drag_N) / (a1 + a2)
    e1 = u_mm - x
    e2 = x - y_mm
    if e1 > 0.0 and e2 > 0.0:
        du = a1 / (a1 + a2)
        dy = a2 / (a1 + a2)
        return (k1_N_per_mm * e1, k2_N_per_mm * e2, x, k1_N_per_mm * (1.0 - du),
                -k1_N_per_mm * dy, k2_N_per_mm * du, k2_N_per_mm * (dy - 1.0))
    if sign > 0.0:  # drawn in against a slack tip end: only the drag holds the rope
        t1 = drag_N / (1.0 - share)
        return t1, 0.0, u_mm - t1 / k1_N_per_mm, 0.0, 0.0, 0.0, 0.0
    t2 = drag_N / (1.0 - share)  # the tip pulls the rope back against a slack drum end
    return 0.0, t2, y_mm + t2 / k2_N_per_mm, 0.0, 0.0, 0.0, 0.0


def shaft_shortening_mm(load_N: float, gap_mm: float, gap_load_N: float,
                        stiffness_N_per_mm: float) -> tuple[float, float]:
    """Axial shortening of the shaft under the ropes' compressive load, and its compliance.

    The coil gaps close first (soft, saturating at ``gap_mm``), then the solid shaft
    compresses linearly: the dead zone grows with the load the other ropes carry.
    """
    f = load_N if load_N > 0.0 else 0.0
    e = math.exp(-f / gap_load_N)
    return gap_mm * (1.0 - e) + f / stiffness_N_per_mm, (
        gap_mm / gap_load_N * e + 1.0 / stiffness_N_per_mm)


def crimp_creep_rate_mm_s(tension_N: float, crept_mm: float, rate_mm_s: float, load_N: float,
                          exponent: float, hardening_mm: float) -> float:
    """Viscoplastic slip rate of the rope out of its swaged pull ring: a power law in the
    load, hardening with the slip so far (log-time creep under a held load)."""
    if tension_N <= 0.0 or rate_mm_s == 0.0:
        return 0.0
    return rate_mm_s * (tension_N / load_N) ** exponent * math.exp(-crept_mm / hardening_mm)


def heart_pulse(t_s: float, rate_hz: float, phase_deg: float) -> float:
    """Zero-mean pulsatile shape of the heart's push on the probe (-0.375 .. 0.625)."""
    s = 0.5 - 0.5 * math.cos(2.0 * math.pi * rate_hz * t_s + math.radians(phase_deg))
    return s * s - 0.375
