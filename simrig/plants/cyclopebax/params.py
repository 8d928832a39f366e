"""Constants of the cyclopebax plant, per knob, with where their values come from.

The plant is an intracardiac/TEE-style probe driven through a cycloidal reducer in the robot's
adapter (one per knob), a partly engaged knob brake, steel wire-rope tendons in a coil-wound
lumen whose friction depends on which way the rope slides (its strand lay against the coil's
winding), a bending section moulded from three Pebax durometers whose neutral axis moves toward
the concave side as it bends, and tendons that take a plastic set when overloaded.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

from simrig.plant import PlantLoadError

SEGMENT_LENGTH_SHARE = (0.40, 0.35, 0.25)
"""Proximal, middle and distal durometer zones of the bending section (share of its length;
a three-zone 72D / 55D / 35D Pebax reflow is the usual steerable-sheath layup)."""
SEGMENT_STIFFNESS_SHARE = (2.6, 1.0, 0.45)
"""Flexural stiffness of each zone relative to the middle one (Pebax 72D ~ 500 MPa, 55D ~ 170,
35D ~ 20-80 MPa; the braid and the lumens' liners narrow the spread to about 6:1)."""
SEGMENT_OVALISING_SHARE = (0.35, 0.55, 0.70)
SEGMENT_OVALISING_BEND_RAD = 0.6
"""Brazier softening: a bent tube ovalises and loses second moment, M = K t ((1 - s) + s / (1 +
(t / t_b)^2)); the braid stops the ovalising at a share s of the stiffness (softer grades, thinner
walls: larger s). Monotone for s < 0.89."""
SEGMENT_AXIS_SHIFT_MM_PER_RAD = (0.30, 0.55, 0.90)
"""Neutral-axis travel toward the concave side per rad of the zone's bend: the compressed side
of a braided polymer tube is stiffer than its stretched side, more so in softer grades. The
pulled rope's arm shrinks and the slack rope's grows: the section takes up both (and both of the
other plane's pair: bending one plane tightens the other)."""

SECTION_LUMEN_FRICTION_SHARE = 0.4
"""The section's own bend wraps the ropes over PTFE lumen tubes, not the shaft's coil: its wrap
counts at 0.4 of the coil's friction (PTFE on steel 0.04-0.08 against 0.1-0.15)."""


@dataclass(frozen=True)
class CycloPebaxKnob:
    """One knob's chain: reducer, brake, drum, two tendons, one plane of the section."""

    reducer_ratio: float = 3.0
    """Knob turns per drum turn (a single-stage cycloidal reducer: ratio = lobes / (lobes - 1)
    is usually 10-80; the adapter's is a low-ratio two-disc stage, design constant)."""
    lost_motion_deg: float = 5.0
    """Knob-side lost motion of the reducer (pin-roller clearance: machined cycloidal drives are
    sold at 1-3 arcmin output, moulded adapter stages at 0.5-2 deg output; 5 deg here is 1.7)."""
    mesh_twist_deg: float = 0.8
    """Knob-side twist of the pin contacts at ``mesh_ref_torque_Nm`` (Hertzian: twist ~ T^2/3)."""
    mesh_ref_torque_Nm: float = 0.2
    mesh_friction: float = 0.30
    """Load-dependent mesh loss: the knob sees (1 + f) of the load while driving and (1 - f)
    while back-driven (cycloidal efficiency 0.8-0.9 at low ratio, lower back-driving)."""
    mesh_presliding_deg: float = 0.3
    drum_radius_mm: float = 21.0
    """Tendon drum on the reducer's output (effective radius at the knob: 7 mm)."""
    drum_friction_Nmm: float = 5.0
    """Drum bushing: holds the drum inside the reducer's clearance when no tendon pulls."""
    handle_friction_Nm: float = 0.02
    """The knob's friction lock as the operator left it, partly engaged."""
    handle_presliding_deg: float = 0.8
    slack_pos_mm: float = 3.0
    slack_neg_mm: float = 3.0
    tendon_stiffness_N: float = 9000.0
    """EA of a 0.36 mm 7x7 steel rope (about 0.065 mm^2 metallic area x 190 GPa x lay
    factor 0.75)."""
    free_length_m: float = 0.12
    sheath_length_m: float = 1.0
    bend_length_mm: float = 70.0
    sheath_wrap_deg: float = 150.0
    """Accumulated curvature of the shaft's path to the heart (a TEE/ICE route: 90-270 deg)."""
    sheath_friction: float = 0.28
    """Mean of the two sliding directions (steel rope in a bare steel coil with little
    lubricant: 0.2-0.35; a PTFE-lined lumen would be 0.05-0.15)."""
    lay_asymmetry: float = 0.25
    """Friction is (1 + a) x the mean when the rope is drawn in against its lay, (1 - a) x when
    it pays out (a right-hand-lay rope in a right-hand coil: the strands ride the coil's turns
    one way and catch them the other)."""
    sheath_drag_N: float = 0.4
    """Load-free drag of the rope in its lumen (seal, coil ovality)."""
    tendon_offset_mm: float = 4.0
    """Lumen to section centre line (a 12-14 Fr section)."""
    bend_stiffness_Nmm_per_rad: float = 30.0
    """Small-bend stiffness of the whole section (three zones in series)."""
    yield_tension_N: float = 15.0
    """Tension at which the rope starts to take a permanent set (the crimp seats on the rope,
    the strands bed in: from 10-20 % of break; a 0.36 mm 7x7 rope breaks at ~110 N)."""
    set_hardening_N_per_mm: float = 40.0
    """Rise of that tension per mm of set already taken (the rope beds in, then holds)."""


NOMINAL_KNOBS = (CycloPebaxKnob(), CycloPebaxKnob(slack_pos_mm=3.1, slack_neg_mm=2.9,
                                                  bend_stiffness_Nmm_per_rad=26.0,
                                                  sheath_wrap_deg=170.0))
"""Knob 1 (anterior-posterior) and knob 2 (right-left: its plane is softer, its lumens further
around the shaft's curve)."""

_POSITIVE = ("reducer_ratio", "mesh_twist_deg", "mesh_ref_torque_Nm", "mesh_presliding_deg",
             "drum_radius_mm", "handle_presliding_deg", "tendon_stiffness_N", "free_length_m",
             "sheath_length_m", "bend_length_mm", "tendon_offset_mm",
             "bend_stiffness_Nmm_per_rad", "yield_tension_N", "set_hardening_N_per_mm")
_NON_NEGATIVE = ("lost_motion_deg", "mesh_friction", "drum_friction_Nmm", "handle_friction_Nm",
                 "slack_pos_mm", "slack_neg_mm", "sheath_wrap_deg", "sheath_friction",
                 "lay_asymmetry", "sheath_drag_N")


def knob_from(values: dict[str, Any] | CycloPebaxKnob, nominal: CycloPebaxKnob) -> CycloPebaxKnob:
    """One knob's constants from a dict of overrides on ``nominal``, checked."""
    if isinstance(values, CycloPebaxKnob):
        knob = values
    else:
        known = {f.name for f in dataclasses.fields(CycloPebaxKnob)}
        unknown = sorted(set(values) - known)
        if unknown:
            raise PlantLoadError(f"unknown cyclopebax knob constants: {', '.join(unknown)}")
        knob = dataclasses.replace(nominal, **{k: float(v) for k, v in values.items()})
    for name in _POSITIVE:
        value = getattr(knob, name)
        if not (math.isfinite(value) and value > 0.0):
            raise PlantLoadError(f"cyclopebax {name} must be > 0, got {value!r}")
    for name in _NON_NEGATIVE:
        value = getattr(knob, name)
        if not (math.isfinite(value) and value >= 0.0):
            raise PlantLoadError(f"cyclopebax {name} must be >= 0, got {value!r}")
    if knob.lay_asymmetry >= 1.0:
        raise PlantLoadError(f"cyclopebax lay_asymmetry must be < 1, got {knob.lay_asymmetry}")
    if knob.mesh_friction >= 0.5:
        raise PlantLoadError(f"cyclopebax mesh_friction must be < 0.5, got {knob.mesh_friction}")
    return knob


UNIT_SCATTER: dict[str, float] = {
    "lost_motion_deg": 0.40,  # pin-roller clearance: moulded discs, tolerance stack
    "mesh_twist_deg": 0.20,  # pin and disc material lot, preload
    "mesh_friction": 0.25,  # grease left from assembly, pin finish
    "drum_radius_mm": 0.02,  # moulded drum
    "drum_friction_Nmm": 0.30,  # drum bushing fit
    "handle_friction_Nm": 0.40,  # the friction lock as the last operator left it
    "slack_pos_mm": 0.15,  # rope wound and crimped by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # wire-rope lot (steel)
    "free_length_m": 0.20,  # adapter and handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "sheath_wrap_deg": 0.10,  # the shaft's path in the patient
    "sheath_friction": 0.15,  # coil liner and rope surface, lubricant
    "lay_asymmetry": 0.30,  # how the rope's lay meets the coil's winding
    "sheath_drag_N": 0.20,  # lumen seal, coil ovality
    "tendon_offset_mm": 0.05,  # lumen placement in the section
    "bend_stiffness_Nmm_per_rad": 0.15,  # Pebax lots of the three zones, reflow
    "yield_tension_N": 0.15,  # crimp swage pressure, rope lot
    "set_hardening_N_per_mm": 0.20,
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
