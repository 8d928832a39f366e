"""Constitutive laws of the stick-slip plant: polymer tendon relaxation, tip chain.

(The braid's toe is inlined in :meth:`KnobRing._tensions`, its one home.)

Pure functions of scalars (the solve calls them a few hundred times per step: no numpy here).
"""

from __future__ import annotations

import math


def prony_factors(dt_s: float, time_s: float) -> tuple[float, float]:
    """Decay ``a`` and strain gain ``b`` of one Maxwell branch over ``dt_s`` (exact for a strain
    that changes linearly within the step: unconditionally stable at any step)."""
    if dt_s <= 0.0:
        return 1.0, 1.0
    r = dt_s / time_s
    a = math.exp(-r)
    return a, (1.0 - a) / r


def tip_moment(theta_rad: float, stiffness_Nm_per_rad: float, stiffening_per_rad2: float,
               links: int, mass_kg: float, length_m: float, gravity_m_s2: float
               ) -> tuple[float, float]:
    """Moment the bending section resists with at ``theta_rad``, and its slope.

    A pseudo-rigid-body chain of ``links`` equal links whose joints share the bend (the tendon's
    moment is the same at every joint), each stiffening as k (1 + c phi^2), carrying its own
    weight with the tip hanging down (as a TEE probe in the oesophagus): the weight pulls the tip
    back to straight, more with the bend's lever arm. Moment = dU/dtheta of the chain's energy.
    """
    n = links
    phi = theta_rad / n
    m_el = stiffness_Nm_per_rad * theta_rad * (1.0 + stiffening_per_rad2 * phi * phi)
    k_el = stiffness_Nm_per_rad * (1.0 + 3.0 * stiffening_per_rad2 * phi * phi)
    if mass_kg <= 0.0:
        return m_el, k_el
    link_m = length_m / n
    scale = (mass_kg / n) * gravity_m_s2 * link_m
    m_g = 0.0
    k_g = 0.0
    for j in range(1, n + 1):
        w = n - j + 0.5  # links beyond joint j, and half of link j itself
        m_g += w * j * math.sin(j * phi)
        k_g += w * j * j * math.cos(j * phi)
    return m_el + scale * m_g / n, k_el + scale * k_g / (n * n)
