"""The laws of the cyclopebax plant, as pure functions (tables built once per plant)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from simrig.plants.cyclopebax.params import (
    SEGMENT_AXIS_SHIFT_MM_PER_RAD,
    SEGMENT_LENGTH_SHARE,
    SEGMENT_OVALISING_BEND_RAD,
    SEGMENT_OVALISING_SHARE,
    SEGMENT_STIFFNESS_SHARE,
)

SECTION_MAX_RAD = 3.6
"""The section's table reaches 206 deg of bend (far beyond any tendon load the knobs make)."""
SECTION_STEP_RAD = 0.004


@dataclass(frozen=True)
class SectionTable:
    """One plane of the three-zone section on a uniform bend grid (0 .. SECTION_MAX_RAD).

    ``moment_Nmm[i]``: moment that holds the bend ``i * step``; ``takeup_mm[i]``: how much the
    neutral axis' travel takes up every rope (E: the convex side lengthens more than the concave
    side shortens); ``takeup_slope_mm[i]``: dE/dbend.
    Odd (moment, slope) and even (take-up) in the bend, so only the positive half is stored.
    """

    moment_Nmm: list[float]
    takeup_mm: list[float]
    takeup_slope_mm: list[float]


def section_table(bend_stiffness_Nmm_per_rad: float) -> SectionTable:
    """Three zones in series carry one moment: each bends by t_k with M = K_k t_k ovalised.

    Zone stiffness K_k = share_k K_mid / length_k with K_mid set so the small-bend stiffness of
    the whole is ``bend_stiffness_Nmm_per_rad``; the neutral axis of zone k moves by
    e_k t_k toward the concave side, taking up every rope by E = sum e_k t_k^2 / 2.
    """
    compliance = sum(length / stiff for length, stiff
                     in zip(SEGMENT_LENGTH_SHARE, SEGMENT_STIFFNESS_SHARE, strict=True))
    k_zone = [bend_stiffness_Nmm_per_rad * compliance * stiff / length for length, stiff
              in zip(SEGMENT_LENGTH_SHARE, SEGMENT_STIFFNESS_SHARE, strict=True)]
    m = np.linspace(0.0, 12.0 * bend_stiffness_Nmm_per_rad, 20001)
    own = np.linspace(0.0, 12.0, 24001)
    zones = []
    for k, s in zip(k_zone, SEGMENT_OVALISING_SHARE, strict=True):
        zone_moment = k * own * (1.0 - s + s / (1.0 + (own / SEGMENT_OVALISING_BEND_RAD) ** 2))
        zones.append(np.interp(m, zone_moment, own))
    bend = np.sum(zones, axis=0)
    takeup = sum(0.5 * e * t * t for e, t in zip(SEGMENT_AXIS_SHIFT_MM_PER_RAD, zones,
                                                strict=True))
    grid = np.arange(0.0, SECTION_MAX_RAD + 0.5 * SECTION_STEP_RAD, SECTION_STEP_RAD)
    moment = np.interp(grid, bend, m)
    pay = np.interp(grid, bend, takeup)
    slope = np.gradient(pay, grid)
    return SectionTable(moment.tolist(), pay.tolist(), slope.tolist())


def section_at(table: SectionTable, bend_rad: float) -> tuple[float, float, float, float]:
    """(moment Nmm, its slope Nmm/rad, take-up E mm, dE/dbend mm) at a signed bend."""
    a = abs(bend_rad)
    x = a / SECTION_STEP_RAD
    i = min(int(x), len(table.moment_Nmm) - 2)
    f = x - i
    m0, m1 = table.moment_Nmm[i], table.moment_Nmm[i + 1]
    e0, e1 = table.takeup_mm[i], table.takeup_mm[i + 1]
    s0, s1 = table.takeup_slope_mm[i], table.takeup_slope_mm[i + 1]
    sign = 1.0 if bend_rad >= 0.0 else -1.0
    return (sign * (m0 + f * (m1 - m0)), (m1 - m0) / SECTION_STEP_RAD,
            e0 + f * (e1 - e0), sign * (s0 + f * (s1 - s0)))


def mesh_twist_deg(torque_Nm: float, twist_ref_deg: float, ref_torque_Nm: float) -> float:
    """Knob-side twist of the reducer's pin contacts under a knob-side torque (Hertz: the
    contact compliance falls with load, twist ~ T^(2/3)); a small preload keeps it finite at
    zero load."""
    pre = 0.05
    return twist_ref_deg * (((abs(torque_Nm) / ref_torque_Nm) + pre) ** (2.0 / 3.0)
                            - pre ** (2.0 / 3.0))


def lumen_contact(y_mm: float, proximal_mm: float, distal_mm: float, k0_N_mm: float,
                  k1_N_mm: float, grip_in: float, grip_out: float, drag_N: float
                  ) -> tuple[float, float, float, float]:
    """One rope's lumen contact: where its material at the contact sits after the step.

    The rope is stretched between the drum end (``proximal_mm``: draw-in less slack and set)
    and the section end (``distal_mm``: what the section takes), with stiffness ``k0`` before
    the contact and ``k1`` after it. The contact holds while T0 <= grip_in T1 + drag (drawn
    in) and T1 <= grip_out T0 + drag (paying out); otherwise it slides to that bound.
    Returns (y, T0, T1, dT1/d distal).
    """
    y_lo = (k0_N_mm * proximal_mm + grip_in * k1_N_mm * distal_mm - drag_N) / (
        k0_N_mm + grip_in * k1_N_mm)
    y_hi = (grip_out * k0_N_mm * proximal_mm + k1_N_mm * distal_mm + drag_N) / (
        grip_out * k0_N_mm + k1_N_mm)
    if y_mm < y_lo:
        y_mm = y_lo
        d_y = grip_in * k1_N_mm / (k0_N_mm + grip_in * k1_N_mm)
    elif y_mm > y_hi:
        y_mm = y_hi
        d_y = k1_N_mm / (grip_out * k0_N_mm + k1_N_mm)
    else:
        d_y = 0.0
    stretch1 = y_mm - distal_mm
    t1 = k1_N_mm * stretch1 if stretch1 > 0.0 else 0.0
    slope = k1_N_mm * (d_y - 1.0) if stretch1 > 0.0 else 0.0
    stretch0 = proximal_mm - y_mm
    t0 = k0_N_mm * stretch0 if stretch0 > 0.0 else 0.0
    return y_mm, t0, t1, slope


def grips(friction: float, lay_asymmetry: float, wrap_rad: float) -> tuple[float, float]:
    """Capstan grip of the lumen drawing in (against the lay) and paying out (with it)."""
    return (math.exp(friction * (1.0 + lay_asymmetry) * wrap_rad),
            math.exp(friction * (1.0 - lay_asymmetry) * wrap_rad))
