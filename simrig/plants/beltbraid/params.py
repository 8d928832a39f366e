"""Constants of the beltbraid plant, per knob (a unit of the family scatters them)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class KnobParams:
    """One knob's drive train, its two ropes and its plane of the section.

    Sources: steel 7x7 rope of 0.35-0.4 mm (EA ~ 10 kN: 0.09 mm^2 metallic area at an effective
    rope modulus ~110 GPa); PTFE-lined braided lumen, mu 0.08-0.15 on steel; a round polyurethane
    belt loop between knob and drum pulleys (Reynolds creep ~ tension difference / EA of the
    belt); a laser-cut steel tube section with notches cut deeper on one side of each plane.
    """

    # handle: spring-return knob (two antagonistic torsion springs preloaded against each other)
    return_preload_Nm: float = 0.0025
    """Torque the preloaded springs need before the knob leaves its centre (a few mNm)."""
    return_rate_Nm_per_rad: float = 0.0015
    """The pair's rate once the knob is off-centre (weak: the rope load dominates)."""
    return_width_deg: float = 2.0
    """Over how many degrees the preload changes side (the springs' seat play)."""
    handle_friction_Nm: float = 0.003
    """Knob shaft seal (Coulomb, smoothed over a few deg/s)."""
    # handle: flat round belt from the knob pulley to the drum pulley (1:1)
    belt_stiffness_Nm_per_rad: float = 8.0
    """Wind-up of the belt loop: both spans stretch with the drum torque."""
    belt_creep_per_Nm: float = 0.03
    """Reynolds creep: the drum slips back by this fraction of the knob travel per Nm of load."""
    seal_drag_N: float = 1.5
    """The handle's bulkhead seal on each taut rope (Coulomb, while the rope slides through it)."""
    # drum and ropes
    drum_radius_mm: float = 5.5
    slack_pos_mm: float = 2.1
    """Slack of the rope pulled by a positive knob angle (crimped by hand)."""
    slack_neg_mm: float = 2.2
    tendon_stiffness_N: float = 20000.0
    """EA of the steel rope."""
    free_length_m: float = 0.08
    """Drum to sheath entry."""
    sheath_length_m: float = 1.0
    contact_fraction: float = 0.35
    """Where along the sheath the friction's centroid lies (the rope's two springs meet there)."""
    # braided lumen: Bouc-Wen microslip with a tension-proportional capacity
    sheath_friction: float = 0.18
    """PTFE liner on steel rope."""
    sheath_wrap_deg: float = 400.0
    """Total wrap of the lumen path (handle routing + the shaft's lay)."""
    sheath_drag_N: float = 0.8
    """Tension-independent friction: the rope's own bending stiffness pressing it into the braid."""
    microslip_floor_mm: float = 0.03
    """Slip the rope needs before the lumen's friction is all mobilised, at zero tension."""
    microslip_length_m: float = 0.10
    """Length of lumen over which the slip zone spreads before the rope slides at the node."""
    # braided shaft: Preisach relays of wire crossings that slip under the ropes' reaction
    braid_slip_mm: float = 0.30
    """Total shortening when every crossing has slipped (shared by all four ropes)."""
    braid_compliance_mm_per_N: float = 0.0015
    """Elastic shortening of the shaft per newton of total rope load."""
    braid_onset_N: float = 4.0
    """Load at which the first crossings slip forward."""
    braid_span_N: float = 45.0
    """Spread of the crossings' forward thresholds above the onset."""
    braid_hold_N: float = 10.0
    """How far the load must fall below a crossing's forward threshold before it slips back."""
    # section: laser-cut tube with asymmetric notches
    tendon_offset_mm: float = 3.0
    """Lumen radius in the section (moment arm of the ropes)."""
    bend_stiffness_Nmm_per_rad: float = 25.0
    """Bending stiffness toward the positive side (the deeper-cut side)."""
    notch_asymmetry: float = 1.2
    """Stiffness toward the negative side over the positive side (shallower notches)."""


NOMINAL_KNOBS = (
    KnobParams(),
    KnobParams(slack_pos_mm=2.25, slack_neg_mm=2.05, bend_stiffness_Nmm_per_rad=22.0,
               notch_asymmetry=1.1, sheath_wrap_deg=420.0, belt_creep_per_Nm=0.035),
)


def knob_params(given: Any, fallback: KnobParams) -> KnobParams:
    """A knob's constants from a ``KnobParams`` or a dict of overrides (unknown names refused)."""
    if isinstance(given, KnobParams):
        return given
    if not isinstance(given, dict):
        raise ValueError(f"beltbraid knob constants must be a dict, got {given!r}")
    names = {f.name for f in dataclasses.fields(KnobParams)}
    unknown = sorted(set(given) - names)
    if unknown:
        raise ValueError(f"unknown beltbraid knob constants: {', '.join(unknown)}")
    return dataclasses.replace(fallback, **{k: float(v) for k, v in given.items()})


UNIT_SCATTER: dict[str, float] = {
    "return_preload_Nm": 0.25,  # spring lot and how far each is wound at assembly
    "return_rate_Nm_per_rad": 0.20,
    "handle_friction_Nm": 0.20,  # knob seal squeeze
    "belt_stiffness_Nm_per_rad": 0.20,  # belt lot (polyurethane cord) and its tension
    "belt_creep_per_Nm": 0.30,  # belt tension at assembly: the least known constant
    "drum_radius_mm": 0.02,  # moulded pulley and drum
    "slack_pos_mm": 0.15,  # rope crimped to the drum by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # rope lot (EA)
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "contact_fraction": 0.10,  # where the shaft's lay concentrates the friction
    "sheath_friction": 0.15,  # liner lot, lubricant
    "sheath_wrap_deg": 0.10,  # routing in the handle, the shaft's lay
    "sheath_drag_N": 0.25,  # rope straightness, lumen fit
    "microslip_floor_mm": 0.30,  # liner compliance
    "braid_slip_mm": 0.30,  # braid angle and pick count of the shaft lot
    "braid_compliance_mm_per_N": 0.15,
    "braid_onset_N": 0.25,  # braid tension at extrusion
    "braid_hold_N": 0.25,
    "tendon_offset_mm": 0.04,  # lumen placement in the section
    "bend_stiffness_Nmm_per_rad": 0.12,  # laser cut (kerf width) and cover durometer
    "notch_asymmetry": 0.05,  # notch depth tolerance
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
