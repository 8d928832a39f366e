"""Constitutive laws of the rackgrease plant, in closed form (plain floats: a step is ~100 flops).

A rope is two elastic spans meeting at its friction centroid in a grease-packed lumen. The
contact there is a pre-sliding spring (grease gel and liner asperities) in series with a slider
that yields at the grease's Bingham yield force plus boundary friction proportional to the sum of
the two spans' tensions (the capstan law at full slip: T_p - T_d = tanh(mu theta / 2)(T_p + T_d)),
and flows with the grease's plastic viscosity. Each span goes slack at zero tension.
"""

from __future__ import annotations

import math

RopeAnswer = tuple[float, float, float, float, float]
"""One rope solved for a given section draw: (proximal tension N, distal tension N, slope of the
distal tension in the section draw N/mm, node mm, anchor mm) - a plain tuple: ~10 solves a step."""


def _spans_root(draw_mm: float, section_mm: float, k1: float, k2: float, c1: float, c2: float,
                kk: float, x0: float, offset_N: float) -> tuple[float, float]:
    """The node position x solving c1 k1 (p - x)+ - c2 k2 (x - w)+ - kk (x - x0) - offset = 0
    (a decreasing piecewise-linear function of x), and dx/dw there."""
    a1, a2 = c1 * k1, c2 * k2
    lo, hi = (draw_mm, section_mm) if draw_mm < section_mm else (section_mm, draw_mm)
    if a1 * (draw_mm - lo) - kk * (lo - x0) - offset_N <= 0.0:
        ip, iw = 1.0, 0.0  # left of both breakpoints: proximal span taut, distal slack
    elif -a2 * (hi - section_mm) - kk * (hi - x0) - offset_N >= 0.0:
        ip, iw = 0.0, 1.0
    elif draw_mm < section_mm:
        ip, iw = 0.0, 0.0
    else:
        ip, iw = 1.0, 1.0
    den = a1 * ip + a2 * iw + kk
    if den <= 0.0:
        return x0, 0.0
    return (a1 * draw_mm * ip + a2 * section_mm * iw + kk * x0 - offset_N) / den, a2 * iw / den


def solve_rope(anchor_mm: float, draw_mm: float, section_mm: float, k1: float, k2: float,
               kc: float, yield_N: float, coulomb: float, viscous_N_per_mm: float
               ) -> RopeAnswer:
    """One rope: a stick trial of its contact, then (if the contact's force exceeds its capacity)
    the slider flows: return mapping on a viscous (Bingham) slider.

    ``draw_mm`` is the rope's proximal end past its slack, ``section_mm`` what the section has
    drawn in at the distal end, ``coulomb`` = tanh(mu theta / 2), ``viscous_N_per_mm`` the
    film's viscosity over the step (eta / dt).
    """
    z = anchor_mm
    x, dxdw = _spans_root(draw_mm, section_mm, k1, k2, 1.0, 1.0, kc, z, 0.0)
    tp = k1 * (draw_mm - x) if draw_mm > x else 0.0
    td = k2 * (x - section_mm) if x > section_mm else 0.0
    force = tp - td
    if abs(force) > yield_N + coulomb * (tp + td):
        s = 1.0 if force > 0.0 else -1.0
        beta = kc / (kc + viscous_N_per_mm)
        x, dxdw = _spans_root(draw_mm, section_mm, k1, k2, 1.0 - beta * s * coulomb,
                              1.0 + beta * s * coulomb, (1.0 - beta) * kc, z,
                              beta * s * yield_N)
        tp = k1 * (draw_mm - x) if draw_mm > x else 0.0
        td = k2 * (x - section_mm) if x > section_mm else 0.0
        capacity = yield_N + coulomb * (tp + td)
        z = (kc * x - s * capacity + viscous_N_per_mm * z) / (kc + viscous_N_per_mm)
    slope = k2 * (dxdw - 1.0) if x > section_mm else 0.0
    return tp, td, slope, x, z


def eddy_torque_Nm(speed_deg_s: float, peak_Nm: float, critical_deg_s: float) -> float:
    """Eddy-current drag of a conducting disc between magnets: linear in speed at low speed,
    a peak at the critical speed, falling beyond it as the skin effect sets in."""
    r = speed_deg_s / critical_deg_s
    return 2.0 * peak_Nm * r / (1.0 + r * r)


def guide_friction_N(tension_N: float, friction: float, offset_mm: float,
                     guide_mm: float) -> float:
    """Friction of a rack cocked in its guide by a pull ``offset_mm`` off its axis: two corner
    reactions of T e / L each, both rubbing (the drawer effect)."""
    return friction * 2.0 * offset_mm / guide_mm * tension_N


def head_moment_Nmm(own_rad: float, other_rad: float, share_Nmm: float) -> float:
    """Gravity's moment on the section from the transducer head, in this plane: the head's lever
    is the axial reach of a constant-curvature section, L sin(b)/b of the total bend b (the
    other plane's bend shortens it: a coupling)."""
    b = math.hypot(own_rad, other_rad)
    reach = math.sin(b) / b if b > 1e-9 else 1.0
    return -share_Nmm * reach


def coulomb_ratio(friction: float, wrap_rad: float) -> float:
    """tanh(mu theta / 2): the capstan law T_p / T_d = exp(mu theta) as a difference over a
    sum."""
    return math.tanh(0.5 * friction * max(0.0, wrap_rad))


SectionAnswer = tuple[float, float, float]
"""The grease's moment on the section (Nmm), its slope in the bend (Nmm/rad), the gel's anchor
(rad)."""


def grease_moment(bend_rad: float, anchor_rad: float, gel_Nmm_per_rad: float, yield_Nmm: float,
                  viscous_Nmm_per_rad: float) -> SectionAnswer:
    """The grease packed around the section's ropes and spine: a gel (elastic below yield) in
    series with a Bingham slider (yield moment, then plastic viscosity over the step,
    ``viscous_Nmm_per_rad`` = eta / dt). Return mapping on the slider."""
    m = gel_Nmm_per_rad * (bend_rad - anchor_rad)
    if abs(m) <= yield_Nmm:
        return m, gel_Nmm_per_rad, anchor_rad
    s = 1.0 if m > 0.0 else -1.0
    beta = gel_Nmm_per_rad / (gel_Nmm_per_rad + viscous_Nmm_per_rad)
    moment = beta * s * yield_Nmm + (1.0 - beta) * gel_Nmm_per_rad * (bend_rad - anchor_rad)
    anchor = ((gel_Nmm_per_rad * bend_rad - s * yield_Nmm + viscous_Nmm_per_rad * anchor_rad)
              / (gel_Nmm_per_rad + viscous_Nmm_per_rad))
    return moment, (1.0 - beta) * gel_Nmm_per_rad, anchor
