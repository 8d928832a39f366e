"""Constants of the snakedent plant, one set per knob, with where each value comes from.

A TEE-sized probe (shaft 9-10 mm, bending section ~40 mm): each plane bends through a stack of
rigid vertebrae that roll on one another (rolling-contact joints), steel wire ropes with slack
drawn in by a drum behind a spring-ball detent wheel, one lumped lumen contact per rope.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from simrig.plant import PlantLoadError


@dataclass(frozen=True)
class SnakeDentKnob:
    """One knob's drive train, ropes and vertebra stack (lengths mm, forces N, torques N m)."""

    drum_radius_mm: float = 3.5
    """Rope drum on the knob shaft (TEE handles: 3-5 mm)."""
    slack_pos_mm: float = 1.62
    """Rope slack at assembly (hand crimped: 1.6 mm, i.e. 27 deg of a 3.5 mm drum; enough for
    the paper's uncompensated errors, PTPE 58-69 deg)."""
    slack_neg_mm: float = 1.67
    tendon_stiffness_N: float = 45000.0
    """Rope EA: a 7x19 steel rope of 0.75 mm (metallic area ~0.24 mm^2 x ~190 GPa)."""
    sheath_length_m: float = 1.0
    """Insertion tube (TEE: ~1 m)."""
    free_length_m: float = 0.15
    """Rope in the handle and the section."""
    sheath_friction: float = 0.20
    """Steel rope on a PTFE-lined coil (boundary, lubricated: 0.1-0.25)."""
    sheath_wrap_deg: float = 270.0
    """Total curve of the shaft: pharynx bend plus the oesophagus and the handle's exit."""
    sheath_drag_N: float = 0.5
    """Tension-independent drag: lumen seals and coil ovality."""
    tendon_offset_mm: float = 2.2
    """Rope hole's distance from the vertebra axis in its plane (d)."""
    roll_radius_mm: float = 3.2
    """Radius of the vertebrae's rolling faces (R)."""
    hole_depth_mm: float = 1.9
    """Depth of the rope hole's exit below the rolling face's apex (h); R - h sets how much
    the rope path lengthens on both sides as a joint rolls."""
    joints: float = 6.0
    """Rolling joints of this plane (the stack alternates the two planes' joints)."""
    bend_stiffness_Nmm_per_rad: float = 140.0
    """Per joint: the central spring spine and the polymer jacket over the stack."""
    joint_friction_mm: float = 0.12
    """Per joint: friction torque per newton of stack compression (sliding at the pins'
    guides, rolling resistance of the faces): mu x lever."""
    joint_preload_N: float = 10.0
    """Stack compression by the spine spring with no rope load."""
    handle_friction_Nm: float = 0.006
    """Knob shaft seal and bearing."""
    detent_torque_Nm: float = 0.0025
    """Peak torque of the spring-ball detent on the knob's indexing wheel."""
    detent_pitch_deg: float = 15.0
    """Angle between detent notches (24 per turn)."""


NOMINAL_KNOBS = (SnakeDentKnob(), SnakeDentKnob(slack_pos_mm=1.72, slack_neg_mm=1.57,
                                                 bend_stiffness_Nmm_per_rad=120.0,
                                                 tendon_offset_mm=2.1))
"""phi1 (anterior-posterior) and phi2 (right-left); the right-left stack is softer."""

_POSITIVE = ("drum_radius_mm", "tendon_stiffness_N", "sheath_length_m", "tendon_offset_mm",
             "roll_radius_mm", "joints", "bend_stiffness_Nmm_per_rad", "detent_pitch_deg")


def knob_from(values: Mapping[str, Any], base: SnakeDentKnob) -> SnakeDentKnob:
    """One knob's constants from keyword overrides, checked (a clear one-line error)."""
    known = {f.name for f in dataclasses.fields(SnakeDentKnob)}
    unknown = sorted(set(values) - known)
    if unknown:
        raise PlantLoadError(f"unknown snakedent knob constants: {', '.join(unknown)}")
    knob = dataclasses.replace(base, **{k: float(v) for k, v in values.items()})
    for name in known:
        value = getattr(knob, name)
        if not math.isfinite(value):
            raise PlantLoadError(f"snakedent {name} must be finite, got {value!r}")
        if name in _POSITIVE and not value > 0.0:
            raise PlantLoadError(f"snakedent {name} must be > 0, got {value!r}")
        if not value >= 0.0:
            raise PlantLoadError(f"snakedent {name} must be >= 0, got {value!r}")
    if not knob.hole_depth_mm <= knob.roll_radius_mm:
        raise PlantLoadError("snakedent hole_depth_mm must be <= roll_radius_mm")
    if not knob.tendon_offset_mm < knob.roll_radius_mm:
        raise PlantLoadError("snakedent tendon_offset_mm must be < roll_radius_mm")
    return knob


UNIT_SCATTER: dict[str, float] = {
    "drum_radius_mm": 0.02,  # moulded drum
    "slack_pos_mm": 0.15,  # rope wound and crimped by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # steel rope lot
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "sheath_wrap_deg": 0.10,  # the shaft's path in the patient
    "sheath_friction": 0.15,  # liner coating, lubricant
    "sheath_drag_N": 0.20,  # lumen seal, coil ovality
    "tendon_offset_mm": 0.04,  # rope holes drilled in each vertebra
    "roll_radius_mm": 0.03,  # ground rolling faces
    "hole_depth_mm": 0.06,  # hole exit below the face (deburring)
    "bend_stiffness_Nmm_per_rad": 0.15,  # spine spring and jacket lots
    "joint_friction_mm": 0.30,  # pin guides' finish, grease
    "joint_preload_N": 0.25,  # spine spring preload at assembly
    "handle_friction_Nm": 0.25,  # knob seal
    "detent_torque_Nm": 0.25,  # detent spring lot, ball seat wear
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
