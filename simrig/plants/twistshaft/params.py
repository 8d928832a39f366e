"""Constants of the twistshaft plant, each with where its magnitude comes from, and their checks.

Per knob (``TwistKnobParams``, scattered by the family) and per shaft (``ShaftParams``, one shaft
carries all four tendons). Lengths in the names' units; the plant converts once at build time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields


@dataclass(frozen=True)
class TwistKnobParams:
    """One knob: its drum, its two antagonistic tendons, their lumens, the bending plane."""

    pulley_radius_mm: float = 8.0
    """Knob drum radius: TEE handles wind the tendons on 6-10 mm drums (paper's rig, 8 mm)."""
    tendon_offset_mm: float = 5.0
    """Lumen distance from the neutral axis: a 12-14 mm TEE tip carries its lumens at 4-6 mm
    (5.0 from 4.5 for the realism checks' loaded slope, 1.2-1.6)."""
    lumen_angle_error_deg: float = 1.5
    """Angular misplacement of this lumen pair off its plane (multi-lumen extrusion tolerance,
    1-3 deg): the other plane's bending lengthens or shortens these tendons' paths."""
    lumen_helix_deg: float = 0.75
    """Helix angle of the lumens in the steerable section (extrusion twist, link stacking:
    0.5-3 deg): tension along a helix twists the section."""
    slack_pos_mm: float = 4.0
    """Tendon length left free when crimped on the drum: 4 mm is 29 knob deg of dead zone on
    8 mm (the paper's catheters and the TEE data: D of tens of knob degrees; 4.0 from 3.0 for
    the paper's uncompensated errors)."""
    slack_neg_mm: float = 4.0
    toe_mm: float = 0.4
    """Braided fibre tendons straighten their strands before they stretch (toe region of
    UHMWPE braids, 0.2-1 % strain over the handle part)."""
    tendon_stiffness_N: float = 9000.0
    """EA of a 0.5 mm UHMWPE braid (modulus ~110 GPa on ~0.08 mm2 of fibre; 9 kN from a first
    6 kN, whose torque fell too slowly at a reversal for the realism check)."""
    free_length_m: float = 0.15
    """Tendon from the drum to the shaft's entry in the handle."""
    sheath_length_m: float = 1.0
    """TEE probe shaft, 1.0-1.1 m."""
    bend_length_mm: float = 60.0
    """Steerable section of a TEE probe, 50-70 mm."""
    sheath_wrap_deg: float = 110.0
    """Total turning of the shaft in the patient (mouth to oesophagus, 90-150 deg): presses each
    tendon on its lumen with tension x wrap."""
    sheath_friction: float = 1.15
    """Low-load friction coefficient of the lumped lumen contact: mu x wrap = 2.2 rad, as a
    braid on a dry polyurethane lumen (mu 0.5-0.7) over 180-250 deg of accumulated turning in a
    TEE shaft (1.15 from 0.72 for the paper's uncompensated errors)."""
    friction_exponent: float = 0.67
    """Friction grows as (normal force)^n above ``contact_load_N``: n = 2/3 for the elastic
    (Hertzian) contact of a polymer asperity field, 0.67-0.9 measured on polymer fibres."""
    contact_load_N: float = 10.0
    """Normal force where the contact turns from its low-load (constant-coefficient) to its
    Hertzian regime (order of the loaded tendon's tension x wrap: the coefficient falls by a
    quarter at full load)."""
    sheath_drag_N: float = 0.025
    """Tension-free drag of the tendon in its lumen (lumen preload, a few 10 mN)."""
    bend_stiffness_Nm_per_rad: float = 0.015
    """Bending stiffness of the tip section: 85 deg of tip at ~4.5 N of tendon on 5 mm, so that
    the knob torque peaks near 0.16 N m (TEE current 150 mA through the rig's 50:1 drive)."""
    handle_friction_Nm: float = 0.0125
    """Knob bearing and O-ring of a TEE handle: 5-20 mN m, a sixth of the loaded knob torque
    (0.0125 from 0.010: the torque falls faster at a reversal)."""
    handle_presliding_deg: float = 1.0
    """Knob rotation over which the bearing friction builds up (elastic seal)."""


@dataclass(frozen=True)
class ShaftParams:
    """The shaft shared by both knobs: its torsion, and the warm-up in the patient."""

    torsion_stiffness_Nm_per_rad: float = 0.015
    """Torsional stiffness of the catheter between handle and tip planes, set by its softest
    part, the steerable section (thin Pebax over links, GJ ~ 1e-3 N m2 over 60 mm; the braided
    1 m shaft, GJ ~ 0.3 N m2, adds little): ~2.5 deg of twist at full load."""
    torsion_friction_Nm: float = 0.0002
    """Rotational friction of the tip section against the oesophagus wall: holds ~0.8 deg of
    twist when the load goes."""
    start_temperature_C: float = 24.0
    """The catheter starts at room temperature (inserted at reset)."""
    body_temperature_C: float = 37.0
    warm_time_s: float = 60.0
    """Time constant of the shaft's warm-up in the patient (polymer wall of ~1 mm in contact with
    tissue: tens of seconds to minutes)."""
    bend_softening_per_C: float = 0.015
    """Relative fall of the tip cover's modulus per deg C (soft Pebax grades, 25-40D: -1 to -2 %/C
    between room and body temperature): -20 % once warm."""
    liner_softening_per_C: float = 0.003
    """Relative fall of the lumen liner's modulus per deg C (PTFE: a fifth of the cover's): a
    softer liner has a larger real contact area."""
    sheath_curvature_deg: float = 0.0
    """Extra curvature of the sheath (the curved-sheath variant): adds to every lumen's wrap."""


def check_knob(k: int, p: TwistKnobParams) -> None:
    """Refuse a constant outside its physical range (one clear line)."""
    for f in fields(p):
        v = getattr(p, f.name)
        if not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ValueError(f"twistshaft knob {k}: {f.name} must be a finite number, got {v!r}")
    positive = ("pulley_radius_mm", "tendon_offset_mm", "tendon_stiffness_N", "free_length_m",
                "sheath_length_m", "bend_length_mm", "bend_stiffness_Nm_per_rad",
                "contact_load_N", "toe_mm", "handle_presliding_deg")
    for name in positive:
        if not getattr(p, name) > 0.0:
            raise ValueError(f"twistshaft knob {k}: {name} must be > 0")
    for name in ("sheath_wrap_deg", "sheath_friction", "sheath_drag_N", "handle_friction_Nm"):
        if getattr(p, name) < 0.0:
            raise ValueError(f"twistshaft knob {k}: {name} must be >= 0")
    if not 0.3 <= p.friction_exponent <= 1.0:
        raise ValueError(f"twistshaft knob {k}: friction_exponent must be in [0.3, 1]")


def check_shaft(p: ShaftParams) -> None:
    for f in fields(p):
        v = getattr(p, f.name)
        if not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ValueError(f"twistshaft: {f.name} must be a finite number, got {v!r}")
    if not p.torsion_stiffness_Nm_per_rad > 0.0 or not p.warm_time_s > 0.0:
        raise ValueError("twistshaft: torsion_stiffness_Nm_per_rad and warm_time_s must be > 0")
    if p.torsion_friction_Nm < 0.0 or p.sheath_curvature_deg < 0.0:
        raise ValueError("twistshaft: torsion_friction_Nm and sheath_curvature_deg must be >= 0")
    for name in ("bend_softening_per_C", "liner_softening_per_C"):
        v = getattr(p, name)
        if not 0.0 <= v * abs(p.body_temperature_C - p.start_temperature_C) < 0.5:
            raise ValueError(f"twistshaft: {name} must be >= 0 and soften by less than half")


UNIT_SCATTER: dict[str, float] = {
    "pulley_radius_mm": 0.02,  # machined drum
    "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
    "lumen_angle_error_deg": 0.50,  # angular tolerance of the extrusion die (1-3 deg)
    "lumen_helix_deg": 0.30,  # extrusion twist: the least controlled geometry
    "slack_pos_mm": 0.15,  # tendon cut and crimped by hand
    "slack_neg_mm": 0.15,
    "toe_mm": 0.20,  # braid lay and crimp
    "tendon_stiffness_N": 0.15,  # braid lot (EA)
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "bend_length_mm": 0.05,  # moulded links
    "sheath_wrap_deg": 0.10,  # lumen path in the shaft
    "sheath_friction": 0.15,  # liner coating, lubricant
    "friction_exponent": 0.05,  # one material pair (0.67-0.9 over materials)
    "contact_load_N": 0.25,  # surface roughness of the liner
    "sheath_drag_N": 0.20,  # lumen preload
    "bend_stiffness_Nm_per_rad": 0.15,  # tip cover and links
    "handle_friction_Nm": 0.20,  # knob bearing / O-ring
    "handle_presliding_deg": 0.20,
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
