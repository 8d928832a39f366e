"""Constants of the planetwist plant, their sources, and the checks that refuse bad ones.

Per knob (phi1 anterior-posterior, phi2 right-left): a planetary stage in the handle (knob on
the sun, drum on the carrier), two stranded steel ropes with slack whose distal ends sit in
swivel crimps, one lumped lumen contact per rope halfway along the sheath, a bending section
that stiffens with its total bend, and the blood flow of a heart chamber pushing on the tip.
Sources (values chosen here, not copied): planetary backlash and per-planet position error of
small plastic/steel handle stages (catalogue figures of 0.3-1 deg at the carrier, errors of a
tenth of a degree); Costello's strand theory for the twist-stretch coupling of a 1x7 strand
(coupling share kappa^2 = C^2/(EA GJ) of 0.3-0.4, untwist per strain C/EA of about lay radius
x lay angle); TEE/ICE probe geometry (0.4-0.5 mm steel ropes, lumens 1.5-2.5 mm off axis, a
1 m shaft, knob 60-90 deg per full bend); blood drag on a 10 Fr shaft at 0.2-0.4 m/s
(0.5 rho Cd d L U^2 about 10 mN on 60 mm).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from simrig.plant import PlantLoadError


@dataclass(frozen=True)
class PlanetTwistKnob:
    """One knob's drive train, ropes and section half (lengths mm or m, torques N mm)."""

    planet_ratio: float = 2.2
    """Sun-to-carrier ratio 1 + Z_ring / Z_sun of the handle's planetary stage."""
    drum_radius_mm: float = 9.0
    carrier_play_deg: float = 2.5
    """Lost motion per side at the carrier (tooth clearance of the stage)."""
    mesh_stiffness_Nmm_per_rad: float = 30000.0
    """One planet's mesh stiffness referred to the carrier."""
    planet2_error_deg: float = 0.12
    """How far the second planet lags the first before it takes load (position error)."""
    planet3_error_deg: float = 0.30
    carrier_stiffness_Nmm_per_rad: float = 100000.0
    drum_bearing_Nmm: float = 40.0
    """Friction of the drum's bearing: inside the play it holds a rope pulling less than
    this over the drum radius."""
    gear_efficiency: float = 0.93
    """Mesh efficiency of the stage: driving divides the load torque by it, back-driving
    multiplies."""
    slack_pos_mm: float = 1.75
    slack_neg_mm: float = 1.75
    tendon_stiffness_N: float = 14000.0
    """EA of the 1x7 strand with its ends held against rotation."""
    twist_coupling_mm: float = 0.04
    """C / EA: the strand's torque per unit strain over its axial stiffness (lay radius x lay
    angle)."""
    twist_share: float = 0.45
    """kappa^2 = C^2 / (EA GJ): the share of axial stiffness lost when the strand may untwist."""
    swivel_friction_Nmm: float = 0.01
    """Friction torque of the swivel crimp at no load (the pull ring's seat)."""
    swivel_arm_mm: float = 0.002
    """Friction torque of the swivel per newton of rope tension (mu x thrust-face radius)."""
    sheath_length_m: float = 1.0
    free_length_m: float = 0.06
    """Rope in the handle between the drum and the sheath."""
    contact_fraction: float = 0.0
    """Where along the sheath the lumped lumen contact sits (0 proximal, 1 distal)."""
    sheath_wrap_deg: float = 260.0
    sheath_friction: float = 0.22
    sheath_drag_N: float = 0.3
    tendon_offset_mm: float = 2.0
    bend_stiffness_Nmm_per_rad: float = 12.0
    bend_stiffening_per_rad2: float = 0.15
    """K = k beta (1 + c (beta^2 + beta_other^2)): the jacket and coil stiffen with the bend."""
    cross_takeup: float = 0.1
    """The other plane's bend takes up this share of a beta_other^2 / 2 of both ropes."""
    shaft_bend_deg_per_N: float = 0.02
    """The ropes' compression rides the shaft wall at the lumen's offset: the shaft between the
    base sensor and the section bends by this much per newton of the pair's mean tension
    difference (a L / EI of a TEE shaft, EI about 0.15 N m^2)."""
    handle_friction_Nm: float = 0.008
    flow_moment_Nmm: float = 0.1
    """Blood drag moment on the section at the flow's mean speed (pushes toward +)."""


NOMINAL_KNOBS = (
    PlanetTwistKnob(),
    PlanetTwistKnob(slack_pos_mm=1.9, slack_neg_mm=1.85, bend_stiffness_Nmm_per_rad=10.5,
                    tendon_offset_mm=1.9, flow_moment_Nmm=0.05, planet2_error_deg=0.18,
                    planet3_error_deg=0.25),
)
"""phi1 (anterior-posterior) and phi2 (right-left): the right-left half is softer and slacker,
and sees less of the flow."""

_POSITIVE = ("planet_ratio", "drum_radius_mm", "mesh_stiffness_Nmm_per_rad",
             "carrier_stiffness_Nmm_per_rad", "tendon_stiffness_N", "twist_coupling_mm",
             "sheath_length_m", "tendon_offset_mm", "bend_stiffness_Nmm_per_rad")
_NON_NEGATIVE = ("carrier_play_deg", "drum_bearing_Nmm", "planet2_error_deg",
                 "planet3_error_deg", "slack_pos_mm", "slack_neg_mm", "twist_share",
                 "swivel_friction_Nmm", "swivel_arm_mm",
                 "free_length_m", "sheath_wrap_deg", "sheath_friction", "sheath_drag_N",
                 "bend_stiffening_per_rad2", "cross_takeup", "shaft_bend_deg_per_N",
                 "handle_friction_Nm")


def check_knob(values: dict[str, Any]) -> PlanetTwistKnob:
    """A knob from a dict of overrides, or a one-line :class:`PlantLoadError`."""
    known = {f.name for f in dataclasses.fields(PlanetTwistKnob)}
    unknown = sorted(set(values) - known)
    if unknown:
        raise PlantLoadError(f"unknown planetwist knob constants: {', '.join(unknown)}")
    try:
        knob = PlanetTwistKnob(**{k: float(v) for k, v in values.items()})
    except (TypeError, ValueError) as exc:
        raise PlantLoadError(f"planetwist knob constants must be numbers: {exc}") from None
    for name in _POSITIVE:
        value = getattr(knob, name)
        if not (math.isfinite(value) and value > 0.0):
            raise PlantLoadError(f"planetwist {name} must be > 0, got {value}")
    for name in _NON_NEGATIVE:
        value = getattr(knob, name)
        if not (math.isfinite(value) and value >= 0.0):
            raise PlantLoadError(f"planetwist {name} must be >= 0, got {value}")
    if not math.isfinite(knob.flow_moment_Nmm):
        raise PlantLoadError(f"planetwist flow_moment_Nmm must be finite, got "
                             f"{knob.flow_moment_Nmm}")
    if not 0.0 < knob.gear_efficiency <= 1.0:
        raise PlantLoadError(f"planetwist gear_efficiency must be in (0, 1], got "
                             f"{knob.gear_efficiency}")
    if not knob.twist_share < 0.9:
        raise PlantLoadError(f"planetwist twist_share must be < 0.9, got {knob.twist_share}")
    if not 0.0 <= knob.contact_fraction < 1.0:
        raise PlantLoadError(f"planetwist contact_fraction must be in [0, 1), got "
                             f"{knob.contact_fraction}")
    if knob.swivel_arm_mm * knob.twist_share >= knob.twist_coupling_mm:
        raise PlantLoadError("planetwist swivel_arm_mm x twist_share must be < "
                             "twist_coupling_mm (the swivel would stiffen the strand)")
    if knob.sheath_friction * math.radians(knob.sheath_wrap_deg) >= 1.5:
        raise PlantLoadError("planetwist sheath_friction x sheath_wrap must be < 1.5 rad "
                             "(the lumped contact would lock)")
    return knob


UNIT_SCATTER: dict[str, float] = {
    "drum_radius_mm": 0.02,  # moulded drum on the carrier
    "carrier_play_deg": 0.30,  # tooth thickness and centre-distance tolerance of the stage
    "mesh_stiffness_Nmm_per_rad": 0.15,  # gear material lot (glass-filled POM)
    "planet2_error_deg": 0.50,  # planet pin positions drilled in the carrier
    "planet3_error_deg": 0.50,
    "carrier_stiffness_Nmm_per_rad": 0.15,
    "drum_bearing_Nmm": 0.30,  # bearing fit and grease
    "gear_efficiency": 0.02,  # grease, mesh finish
    "slack_pos_mm": 0.15,  # strand cut and crimped by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # strand lot
    "twist_coupling_mm": 0.10,  # lay length of the strand lot
    "twist_share": 0.10,
    "swivel_friction_Nmm": 0.30,  # swivel crimp's seat finish
    "swivel_arm_mm": 0.20,
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "sheath_wrap_deg": 0.10,  # the shaft's path in the patient
    "sheath_friction": 0.15,  # liner coating, lubricant
    "sheath_drag_N": 0.20,  # lumen seal
    "tendon_offset_mm": 0.04,  # lumen placement in the extrusion
    "bend_stiffness_Nmm_per_rad": 0.15,  # jacket and coil lots
    "bend_stiffening_per_rad2": 0.20,
    "handle_friction_Nm": 0.25,  # knob seal
    "flow_moment_Nmm": 0.40,  # where in the chamber the tip sits (not the catheter's part)
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
