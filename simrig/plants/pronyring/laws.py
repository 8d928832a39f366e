"""The pronyring catheter's constitutive laws, as small pure functions (unit-testable).

* ``liner_friction``: PTFE on steel, the coefficient falling with the rope's load.
* ``rope_contact``: one rope, a proximal and a distal part joined at the path's friction
  centroid (the oropharyngeal bend); the centroid sticks until the tension jump across it
  exceeds the capstan ratio (Euler-Eytelwein over the path's wrap) plus the lumen's drag, then
  slides.
* ``prony_moment``: the Pebax section's moment, long-term spring plus three Maxwell branches,
  advanced implicitly (backward Euler: unconditionally stable at the rig's 4 ms step).
"""

from __future__ import annotations

import math
from typing import NamedTuple


def liner_friction(mu_ref: float, load_N: float, reference_N: float, exponent: float) -> float:
    """PTFE's friction coefficient at ``load_N``: ``mu_ref * (load / reference)^-exponent``,
    the load floored at a tenth of the reference (a rope barely touching its lumen)."""
    load = max(load_N, 0.1 * reference_N)
    return mu_ref * (load / reference_N) ** (-exponent)


class RopeState(NamedTuple):
    proximal_N: float
    """Tension at the drum (what the knob feels)."""
    distal_N: float
    """Tension at the pull ring (what bends the section)."""
    centroid_mm: float
    """Displacement of the rope's material point at the friction centroid."""
    distal_slope_N_per_mm: float
    """d(distal tension)/d(distal displacement demand) on this branch (<= 0)."""


def rope_contact(drum_mm: float, ring_mm: float, centroid_mm: float, proximal_N_per_mm: float,
                 distal_N_per_mm: float, ratio: float, drag_N: float) -> RopeState:
    """One rope's tensions for a drum draw-in past slack ``drum_mm`` and a ring demand ``ring_mm``
    (the rope length the section's bend takes), starting from the centroid at ``centroid_mm``.

    The halves (stiffness ``proximal_N_per_mm`` and ``distal_N_per_mm``) carry only tension. The
    centroid sticks while ``T_p / ratio - drag <= T_d <= T_p * ratio + drag``.
    """
    kp, kd = proximal_N_per_mm, distal_N_per_mm
    z = centroid_mm
    tp = kp * (drum_mm - z) if drum_mm > z else 0.0
    td = kd * (z - ring_mm) if z > ring_mm else 0.0
    if tp / ratio - drag_N <= td <= tp * ratio + drag_N:
        return RopeState(tp, td, z, -kd if z > ring_mm else 0.0)
    if td < tp / ratio - drag_N:  # the drum pulls the rope through: the centroid moves proximally
        c = kp / ratio
        z = (kd * ring_mm + c * drum_mm - drag_N) / (kd + c)
        if z <= ring_mm:  # distal half slack: the drum side only overcomes the drag
            z = drum_mm - ratio * drag_N / kp
            return RopeState(kp * (drum_mm - z), 0.0, z, 0.0)
        return RopeState(kp * (drum_mm - z), kd * (z - ring_mm), z, -kd * c / (kd + c))
    c = kp * ratio  # the ring pulls the rope back: the centroid moves distally
    z = (kd * ring_mm + c * drum_mm + drag_N) / (kd + c)
    if z >= drum_mm:  # proximal half slack: the ring side only overcomes the drag
        z = ring_mm + drag_N / kd
        return RopeState(0.0, drag_N, z, 0.0)
    return RopeState(kp * (drum_mm - z), kd * (z - ring_mm), z, -kd * c / (kd + c))


def prony_moment(bend_rad: float, branches: tuple[tuple[float, float, float], ...],
                 long_term_Nmm_per_rad: float, dt_s: float) -> tuple[float, float]:
    """The section's moment (N mm) and stiffness (N mm/rad) at ``bend_rad`` after ``dt_s``, each
    branch ``(stiffness, relaxation time s, its dashpot's bend rad)`` relaxing toward the bend."""
    moment = long_term_Nmm_per_rad * bend_rad
    stiffness = long_term_Nmm_per_rad
    for k, tau, rest in branches:
        w = k / (1.0 + dt_s / tau)
        moment += w * (bend_rad - rest)
        stiffness += w
    return moment, stiffness


def relax(rest_rad: float, bend_rad: float, tau_s: float, dt_s: float) -> float:
    """A Maxwell branch's dashpot bend after ``dt_s`` (backward Euler)."""
    a = dt_s / tau_s
    return (rest_rad + a * bend_rad) / (1.0 + a)


def capstan_ratio(mu: float, wrap_rad: float) -> float:
    """Euler-Eytelwein ratio of the tensions on either side of a contact of total wrap."""
    return math.exp(mu * max(wrap_rad, 0.0))
