"""Constants of the rackgrease plant, per knob (what a unit's scatter draws).

Sources are named in docs/plant.md ("A twenty-first plant, written blind: rackgrease"); the
values are a small TEE/ICE handle's, chosen so that the nominal unit passes the realism checks.
"""

from __future__ import annotations

from dataclasses import dataclass, fields


@dataclass(frozen=True)
class KnobConstants:
    """One knob's drive train: pinion and rack, two ropes in grease-packed lumens, the section."""

    pinion_radius_mm: float = 5.0
    """Pitch radius of the knob's pinion: rack travel per knob radian."""
    rack_offset_mm: float = 6.0
    """How far the ropes' anchors sit off the rack's guide axis (the pull cocks the rack)."""
    guide_length_mm: float = 18.0
    """Length of the rack's guide bushing: the cocking couple's lever."""
    guide_friction: float = 0.35
    """Friction coefficient of the rack on its guide (acetal on brass)."""
    handle_friction_Nm: float = 0.008
    """Knob torque of the guide's preload (a wave spring against the rack)."""
    eddy_peak_Nm: float = 0.02
    """Peak torque of the eddy-current disc on the pinion shaft."""
    eddy_critical_deg_s: float = 150.0
    """Knob speed at which the eddy-current torque peaks (skin effect beyond it)."""
    slack_pos_mm: float = 2.20
    """Slack of the rope the rack pulls when the knob turns positive."""
    slack_neg_mm: float = 2.35
    tendon_stiffness_N: float = 35000.0
    """Axial stiffness EA of a 1x19 stainless rope, 0.45 mm."""
    free_length_m: float = 0.50
    """Rope from the rack to the shaft's entry (handle)."""
    sheath_length_m: float = 1.0
    """Shaft length; the rope's friction centroid sits at ``contact_fraction`` of it."""
    contact_fraction: float = 0.30
    section_length_m: float = 0.05
    sheath_friction: float = 0.18
    """Boundary friction coefficient of the rope on the lumen wall through the grease film."""
    sheath_wrap_deg: float = 350.0
    """Wrap of the shaft's path (handle routing, oropharynx, oesophagus)."""
    section_wrap_fraction: float = 0.25
    """Share of the section's total bend (both planes) the ropes wrap before the centroid."""
    sheath_drag_N: float = 0.3
    """Drag of the rope in its lumen independent of its load (the liner's fit)."""
    grease_viscosity_N_s_per_mm: float = 0.05
    """Viscous drag of the lubricant film on the sliding rope."""
    contact_stiffness_N_per_mm: float = 400.0
    """Pre-sliding stiffness of the rope's lumen contact (liner asperities)."""
    tendon_offset_mm: float = 2.70
    """Rope lumen offset from the section's neutral axis."""
    bend_stiffness_Nmm_per_rad: float = 25.0
    """Bending stiffness of the section (spine and cover)."""
    section_yield_Nmm: float = 3.2
    """Yield moment of the grease packed in the section (Bingham yield stress over the ropes'
    and spine's sliding surfaces, times their offsets)."""
    section_gel_Nmm_per_rad: float = 2000.0
    """Stiffness of the grease gel below yield, as a moment on the section."""
    section_viscosity_Nmm_s_per_rad: float = 3.0
    """Plastic viscosity of the flowing grease, as a moment per bend rate."""
    head_moment_Nmm: float = 1.2
    """Transducer head weight x its lever, the share of gravity in this knob's plane."""


NOMINAL_KNOBS: tuple[KnobConstants, KnobConstants] = (
    KnobConstants(),
    KnobConstants(slack_pos_mm=2.30, slack_neg_mm=2.15, tendon_offset_mm=2.65,
                  bend_stiffness_Nmm_per_rad=24.0, head_moment_Nmm=0.35,
                  contact_fraction=0.32, rack_offset_mm=6.5),
)
"""Anterior-posterior (knob 1) and right-left (knob 2); the patient lies in left lateral
decubitus, so gravity acts mostly in the anterior-posterior plane and a little right-left."""

FIELD_NAMES = frozenset(f.name for f in fields(KnobConstants))


def knob_constants(values: KnobConstants | dict[str, float]) -> KnobConstants:
    """A knob's constants from a dataclass or a family member's dict (unknown names refused)."""
    if isinstance(values, KnobConstants):
        return values
    unknown = set(values) - FIELD_NAMES
    if unknown:
        raise TypeError(f"unknown rackgrease knob constants: {sorted(unknown)}")
    return KnobConstants(**values)


UNIT_SCATTER: dict[str, float] = {
    "pinion_radius_mm": 0.02,  # moulded pinion
    "rack_offset_mm": 0.10,  # where the rope anchors are crimped on the rack
    "guide_friction": 0.20,  # acetal rack on its brass guide, assembly grease
    "handle_friction_Nm": 0.25,  # wave-spring preload of the guide
    "eddy_peak_Nm": 0.15,  # magnet strength and air gap of the eddy disc
    "slack_pos_mm": 0.15,  # rope crimped to the rack by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # rope lot (EA)
    "free_length_m": 0.15,  # handle routing
    "sheath_length_m": 0.02,  # cut to length
    "contact_fraction": 0.10,  # where the shaft's lay concentrates the friction
    "sheath_friction": 0.15,  # liner lot, lubricant
    "sheath_wrap_deg": 0.10,  # routing in the handle, the shaft's lay
    "sheath_drag_N": 0.25,  # rope straightness, lumen fit
    "section_yield_Nmm": 0.25,  # grease fill of the section (amount, batch consistency)
    "section_gel_Nmm_per_rad": 0.25,
    "section_viscosity_Nmm_s_per_rad": 0.25,
    "tendon_offset_mm": 0.04,  # lumen placement in the section
    "bend_stiffness_Nmm_per_rad": 0.12,  # spine cut and cover durometer
    "head_moment_Nmm": 0.10,  # transducer head mass and where it sits
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
