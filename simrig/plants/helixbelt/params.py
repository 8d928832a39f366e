"""Constants of the helixbelt plant, per knob, with where each value comes from.

One knob drives one plane: a toothed belt from the knob's pulley to the tendon drum (tooth
clearance, progressive tooth-mesh stiffness), two steel wire-rope tendons wound on the drum with
hand-set slack, routed in a helix along a braided shaft (one lumped lumen contact per tendon
whose wrap is the helix's and the shaft's curvature combined), and a braided bending section
(per-plane stiffness, inter-wire friction as a Masing hysteresis).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields


@dataclass(frozen=True)
class HelixKnobParams:
    """One knob's plane. Lengths mm or m as named, forces N, moments Nm, angles deg."""

    pulley_radius_mm: float = 7.2
    """Tendon drum radius (the belt's two pulleys are equal: knob and drum turn alike); R/a = 1.6
    sets the loaded slope, 1.32 on the nominal unit (the paper's catheters: 1.32 +- 0.12)."""
    belt_clearance_deg: float = 3.0
    """Tooth clearance of the belt at the drum, total (both flanks): the drum floats in it
    while neither tendon pulls. 0.2-0.5 mm on a 2 mm pitch (GT2/MXL tooth vs groove), on a
    9 mm pulley about 1.3-3 deg."""
    belt_ref_torque_Nm: float = 0.2
    belt_ref_deflection_deg: float = 5.0
    """Mesh deflection (past the clearance) at the reference torque: a 3 mm MXL belt over 60 mm
    spans (EA ~ 2 kN: ~35 N/mm) and its teeth, 0.65 mm at the pulley's pitch line under 27 N.
    Tooth-mesh stiffness grows with load as more of each tooth flank and more teeth bear:
    deflection ~ sqrt(torque)."""
    slack_pos_mm: float = 3.1
    slack_neg_mm: float = 3.1
    """Tendon slack at assembly (each tendon crimped and wound by hand)."""
    tendon_stiffness_N: float = 15000.0
    """EA of a 7x19 stainless rope of 0.45 mm (metallic area ~0.1 mm^2, rope modulus ~0.75 of
    the wire's 193 GPa)."""
    free_length_m: float = 0.16
    """Tendon from the drum to the shaft's entry, along the handle (a TEE handle is ~0.2 m)."""
    sheath_length_m: float = 1.0
    """Shaft length of a TEE probe (about 1 m to the bending section)."""
    helix_radius_mm: float = 3.0
    """Lumen distance from the shaft axis (a 9-10 mm TEE shaft)."""
    helix_pitch_mm: float = 100.0
    """Length of one turn of the tendons' helix along the shaft (kappa_h = 0.0114 /mm: about
    11 rad of wrap over 1 m - the price a helix pays for a length that ignores the shaft's
    curve)."""
    sheath_wrap_deg: float = 60.0
    """Bend of the shaft's own lay (the probe's path from the handle through the mouth)."""
    sheath_friction: float = 0.12
    """Steel rope on a PTFE lumen liner (0.05-0.1 on smooth wire; more with the rope's strand
    texture). With the helix's wrap mu Theta ~ 1.4: the tendon loses ~3/4 of its tension."""
    sheath_drag_N: float = 0.08
    """Tension-independent drag of the rope in its lumen (liner ovality, braid pressing in)."""
    tendon_offset_mm: float = 4.5
    """Moment arm of the tendon in the bending section."""
    bend_length_mm: float = 60.0
    bend_stiffness_Nm_per_rad: float = 0.015
    """The braided bending section's stiffness in this plane (braid and polymer cover)."""
    braid_stiffening_per_rad2: float = 0.04
    """Braid wires lock as the section bends either way: stiffness x (1 + this x total bend^2)."""
    braid_friction_Nm: float = 0.001
    """Saturated inter-wire friction moment of the braid (the Masing backbone's limit)."""
    braid_slip_deg: float = 3.0
    """Bend over which the braid's friction builds up (backbone tanh scale)."""
    plane_error_deg: float = 3.0
    """The helix's phase where the lumens enter the bending section, off the handle's plane:
    the tip bends this far out of the knob's plane (cross-coupling)."""
    handle_friction_Nm: float = 0.008
    """Knob shaft seal and bearing friction (felt by the motor only)."""

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not math.isfinite(value):
                raise ValueError(f"helixbelt knob constant {f.name} must be finite, got {value}")
        positive = ("pulley_radius_mm", "belt_ref_torque_Nm", "belt_ref_deflection_deg",
                    "tendon_stiffness_N", "sheath_length_m", "helix_radius_mm",
                    "helix_pitch_mm", "tendon_offset_mm", "bend_length_mm",
                    "bend_stiffness_Nm_per_rad", "braid_slip_deg")
        for name in positive:
            if not getattr(self, name) > 0.0:
                raise ValueError(f"helixbelt knob constant {name} must be > 0, "
                                 f"got {getattr(self, name)}")
        non_negative = ("belt_clearance_deg", "slack_pos_mm", "slack_neg_mm", "free_length_m",
                        "sheath_wrap_deg", "sheath_friction", "sheath_drag_N",
                        "braid_stiffening_per_rad2", "braid_friction_Nm", "handle_friction_Nm")
        for name in non_negative:
            if not getattr(self, name) >= 0.0:
                raise ValueError(f"helixbelt knob constant {name} must be >= 0, "
                                 f"got {getattr(self, name)}")
        if not abs(self.plane_error_deg) < 45.0:
            raise ValueError(f"helixbelt plane_error_deg must be within +-45, "
                             f"got {self.plane_error_deg}")


NOMINAL_KNOBS = (HelixKnobParams(), HelixKnobParams(plane_error_deg=-2.0, slack_pos_mm=3.4,
                                                     bend_stiffness_Nm_per_rad=0.0135))
"""Nominal unit: the right-left plane's braid is a little softer (the braid is wound for the
anterior plane) and its tendons were wound with a little more slack."""


UNIT_SCATTER: dict[str, float] = {
    "pulley_radius_mm": 0.02,  # moulded belt pulley and drum
    "belt_clearance_deg": 0.30,  # tooth vs groove: moulding tolerance of two parts
    "belt_ref_deflection_deg": 0.20,  # belt lot (cord and tooth rubber) and its tension
    "slack_pos_mm": 0.15,  # tendon wound and crimped by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # wire-rope lot (steel: less than polymer)
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "helix_pitch_mm": 0.10,  # lumen twist of the extrusion (set by haul-off vs rotation)
    "helix_radius_mm": 0.03,  # lumen placement in the extrusion
    "sheath_wrap_deg": 0.10,  # the shaft's lay
    "sheath_friction": 0.15,  # liner and rope surface
    "sheath_drag_N": 0.20,  # lumen ovality
    "tendon_offset_mm": 0.05,  # lumen placement in the bending section
    "bend_length_mm": 0.03,  # braided section cut to length
    "bend_stiffness_Nm_per_rad": 0.15,  # braid angle and cover durometer
    "braid_stiffening_per_rad2": 0.20,
    "braid_friction_Nm": 0.25,  # inter-wire friction: braid tension and lubricity
    "braid_slip_deg": 0.20,
    "plane_error_deg": 0.50,  # helix phase at the section: extrusion twist over 1 m
    "handle_friction_Nm": 0.20,  # knob shaft seal squeeze
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
