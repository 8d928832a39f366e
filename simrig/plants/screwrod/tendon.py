"""One UHMWPE tendon: toe-then-linear fibre, Iwan sheath contact, slow plastic elongation.

The tendon runs from its nut on the knob collar to a contact that stands for the sheath (the
whole sheath's friction acts there), then on to the tip. The contact is an Iwan (parallel
Jenkins) element set: each element holds its share of the contact's capacity and slips after its
own travel, so the friction turns round gradually (Masing). The capacity is a liner preload plus
``2 tanh(mu x wrap / 2)`` times the mean of the tensions on either side (the normal force of a
tendon pulled round a curved sheath), so friction grows with the load and at full slip the two
sides stand in the capstan ratio ``exp(mu x wrap)``.
"""

from __future__ import annotations

from dataclasses import dataclass

from simrig.plants.screwrod.params import IWAN_SHARES, IWAN_SLIP_FRACTIONS


@dataclass
class TendonState:
    """What one tendon remembers between steps (metres)."""

    contact_m: float = 0.0
    """Displacement of the tendon at the sheath contact (towards the handle)."""
    slip: tuple[float, float, float] = (0.0, 0.0, 0.0)
    """Each Iwan element's normalised force, -1..1 (1: slipping towards the handle)."""
    creep_m: float = 0.0
    """Plastic elongation so far."""


def fibre(elongation_m: float, stiffness_N_per_m: float, toe_m: float) -> tuple[float, float]:
    """(tension N, dT/d elongation) of a braid that is slack below 0, stiffens over the toe
    (quadratic) and is linear beyond it; slope continuous."""
    if elongation_m <= 0.0:
        return 0.0, 0.0
    if elongation_m < toe_m:
        return 0.5 * stiffness_N_per_m * elongation_m * elongation_m / toe_m, (
            stiffness_N_per_m * elongation_m / toe_m)
    return stiffness_N_per_m * (elongation_m - 0.5 * toe_m), stiffness_N_per_m


def iwan(state: TendonState, contact_m: float, presliding_m: float
         ) -> tuple[float, float, tuple[float, float, float]]:
    """(sum of share x normalised force, its slope per metre, the elements' new states) for the
    contact moved from the state's position to ``contact_m``."""
    move = contact_m - state.contact_m
    total, slope = 0.0, 0.0
    new = []
    for share, frac, z0 in zip(IWAN_SHARES, IWAN_SLIP_FRACTIONS, state.slip, strict=True):
        travel = frac * presliding_m
        z = z0 + move / travel
        if z >= 1.0:
            z = 1.0
        elif z <= -1.0:
            z = -1.0
        else:
            slope += share / travel
        total += share * z
        new.append(z)
    return total, slope, (new[0], new[1], new[2])
