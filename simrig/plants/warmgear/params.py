"""Constants of the warmgear plant, per knob, with where each value comes from.

One knob turns a spur pinion that drives the tendon drum of one plane; the drum pulls two steel
wire-rope tendons along a fluid-filled sheath to a bending section stiffer in one plane than in
the other. The shaft warms from room to body temperature after insertion.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from simrig.plant import PlantLoadError


@dataclass(frozen=True)
class WarmGearKnobParams:
    """One knob's plane: handle gear, tendon pair, sheath film and its share of the section."""

    pinion_teeth: float = 15.0
    """Knob pinion (moulded POM, module 0.5): 15 teeth, one mesh period per 24 deg of knob."""
    drum_teeth: float = 20.0
    """Drum gear: the drum turns 15/20 of the knob."""
    gear_play_deg: float = 3.2
    """Circumferential backlash of the mesh at the drum (0.28 mm at a 5 mm pitch radius:
    moulded gears on a loose centre distance, beyond ISO 1328 class 12; set with the slack
    to give the paper's uncompensated errors)."""
    mesh_stiffness_Nmm_per_deg: float = 90.0
    """Drum-side mesh stiffness, averaged over a mesh period (POM teeth, 2 mm face: about
    2e5 N/m of tooth pair at a 5 mm pitch radius, polymer-gear tooth compliance)."""
    mesh_ripple: float = 0.15
    """Half-swing of the mesh stiffness between single- and double-tooth contact (contact
    ratio about 1.5: two pairs carry half of every mesh period)."""
    mesh_friction: float = 0.22
    """Sliding friction at the tooth flanks (POM on POM, dry: 0.2-0.3); the loss is zero at
    the pitch point and largest at the ends of the path of contact."""
    drum_friction_Nmm: float = 2.5
    """Drum bearing (bushing and shaft seal) friction torque."""
    pulley_radius_mm: float = 10.2
    """Tendon drum radius."""
    slack_pos_mm: float = 3.3
    """Tendon slack at room temperature, as assembled (hand crimped)."""
    slack_neg_mm: float = 3.3
    tendon_stiffness_N: float = 11000.0
    """EA of a 0.35 mm 7x7 stainless wire rope (about 0.073 mm^2 at an effective 150 GPa)."""
    free_length_m: float = 0.15
    """Tendon in the handle, drum to shaft entry."""
    sheath_length_m: float = 1.0
    """Shaft from the handle to the bending section (TEE probe: about 1 m)."""
    contact_position: float = 0.3
    """Where along the shaft its laid curve (mouth and pharynx) rubs the tendon: the shaft's
    friction is lumped there, the section's at the section."""
    inserted_share: float = 0.75
    """Share of the shaft that warms to body temperature once inserted."""
    thermal_mismatch_per_K: float = 2.2e-5
    """Axial expansion of the braided Pebax shaft (about 4e-5 /K) minus that of the steel
    tendon (1.7e-5 /K): warm, the lumen grows longer than its tendon and the slack shrinks."""
    sheath_wrap_deg: float = 100.0
    """Angle the shaft turns through from the handle to the section, as laid."""
    sheath_friction: float = 0.40
    """Boundary friction of the strand on the liner once the film is squeezed out (steel on
    a Pebax/nylon liner, dry: 0.3-0.5; the lumped contact also carries the strand's own
    bending and the liner's ovality)."""
    film_friction: float = 0.20
    """Friction with a full film (a flushed, fluid-filled lumen: half the boundary level)."""
    sheath_drag_N: float = 0.25
    """Rubbing of the rope at no tension (lumen ovality)."""
    film_viscous_N_s_per_mm: float = 0.08
    """Shear of the film with a full film at room temperature: the drag per mm/s of rope."""
    squeeze_time_s: float = 3.0
    """Time a 10 N contact takes to squeeze the film from full to 58 % (Reynolds squeeze:
    thickness ~ 1/sqrt(1 + 2 t/tau) under constant load), at room temperature."""
    entrain_length_mm: float = 1.5
    """Rope travel that drags the film back to full (hydrodynamic entrainment)."""
    rewet_time_s: float = 40.0
    """Film recovery of an unloaded contact by capillary flow."""
    tendon_offset_mm: float = 4.5
    """Lumen offset from the neutral axis in the bending section (a TEE probe's section is
    10-14 mm across)."""
    bend_stiffness_Nm_per_rad: float = 0.036
    """Section stiffness in this plane at room temperature (Pebax cover and a laser-cut
    spine cut for one preferred plane)."""
    bend_stiffening_per_rad2: float = 0.0
    """Stiffening with the section's total bend (both planes), cover stretch: none measurable
    on the nominal spine over +-90 deg (a switch for other designs, not scattered)."""
    section_softening_per_K: float = 0.008
    """Pebax 40D loses about 0.8 %/K of its modulus between 20 and 40 C."""
    handle_friction_Nm: float = 0.004
    """Knob shaft O-ring."""


@dataclass(frozen=True)
class ShaftParams:
    """What the two planes share: temperatures, warm-up and the section's wrap coupling."""

    room_C: float = 22.0
    body_C: float = 37.0
    warm_time_s: float = 150.0
    """Time constant of the shaft's warm-up in the oesophagus (thin polymer wall and saline:
    a first-order lag of minutes)."""
    bend_wrap_share: float = 0.5
    """Share of the section's total bend that is the wrap of the section's contact (both
    planes: the other plane's bend adds friction to this one's tendons)."""


_NOMINAL_PHI1 = WarmGearKnobParams()
_NOMINAL_PHI2 = dataclasses.replace(
    _NOMINAL_PHI1, bend_stiffness_Nm_per_rad=0.028, tendon_offset_mm=4.3, slack_pos_mm=3.1,
    slack_neg_mm=3.2, pulley_radius_mm=9.6)
NOMINAL_KNOBS: tuple[WarmGearKnobParams, WarmGearKnobParams] = (_NOMINAL_PHI1, _NOMINAL_PHI2)
"""phi1 (anterior-posterior) and phi2 (right-left): the section is softer right-left."""

_POSITIVE = ("pinion_teeth", "drum_teeth", "mesh_stiffness_Nmm_per_deg", "pulley_radius_mm",
             "tendon_stiffness_N", "sheath_length_m", "squeeze_time_s", "entrain_length_mm",
             "rewet_time_s", "tendon_offset_mm", "bend_stiffness_Nm_per_rad",
             "film_viscous_N_s_per_mm", "contact_position")
_NON_NEGATIVE = ("gear_play_deg", "mesh_friction", "drum_friction_Nmm", "free_length_m",
                 "inserted_share", "sheath_wrap_deg", "sheath_friction", "film_friction",
                 "sheath_drag_N", "bend_stiffening_per_rad2",
                 "section_softening_per_K", "handle_friction_Nm")


def knob_params(knobs: Sequence[Mapping[str, Any]] | None) -> tuple[WarmGearKnobParams, ...]:
    """Both knobs' constants: the nominal ones with ``knobs[i]``'s overrides, checked."""
    if knobs is None:
        return NOMINAL_KNOBS
    if len(knobs) != 2:
        raise PlantLoadError(f"warmgear takes 2 knobs, got {len(knobs)}")
    names = {f.name for f in dataclasses.fields(WarmGearKnobParams)}
    out = []
    for nominal, given in zip(NOMINAL_KNOBS, knobs, strict=True):
        unknown = sorted(set(given) - names)
        if unknown:
            raise PlantLoadError(f"unknown warmgear knob constants: {', '.join(unknown)}")
        p = dataclasses.replace(nominal, **{k: float(v) for k, v in given.items()})
        _check(p)
        out.append(p)
    return tuple(out)


def _check(p: WarmGearKnobParams) -> None:
    for name in _POSITIVE:
        value = getattr(p, name)
        if not (math.isfinite(value) and value > 0.0):
            raise PlantLoadError(f"warmgear {name} must be > 0, got {value!r}")
    for name in _NON_NEGATIVE:
        value = getattr(p, name)
        if not (math.isfinite(value) and value >= 0.0):
            raise PlantLoadError(f"warmgear {name} must be >= 0, got {value!r}")
    if not (math.isfinite(p.slack_pos_mm) and math.isfinite(p.slack_neg_mm)):
        raise PlantLoadError("warmgear slack_pos_mm and slack_neg_mm must be finite")
    if not p.film_friction <= p.sheath_friction:
        raise PlantLoadError("warmgear film_friction must not exceed sheath_friction "
                             "(a full film rubs less than a squeezed one)")
    if not (0.0 <= p.mesh_ripple < 1.0 and p.inserted_share <= 1.0
            and p.contact_position < 1.0):
        raise PlantLoadError("warmgear mesh_ripple must be in [0, 1), inserted_share <= 1 "
                             "and contact_position < 1")


UNIT_SCATTER: dict[str, float] = {
    "gear_play_deg": 0.30,  # moulded gears: tolerance stack of two parts and a centre distance
    "mesh_stiffness_Nmm_per_deg": 0.20,  # POM lot, moisture, face width
    "mesh_friction": 0.20,  # flank finish, grease left from assembly
    "drum_friction_Nmm": 0.25,  # bushing fit and seal squeeze
    "pulley_radius_mm": 0.02,  # moulded drum
    "slack_pos_mm": 0.15,  # tendon wound and crimped by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # wire-rope lot (steel)
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "inserted_share": 0.15,  # how deep the probe sits (the patient)
    "thermal_mismatch_per_K": 0.20,  # shaft braid angle and Pebax lot
    "sheath_wrap_deg": 0.10,  # the shaft's lay
    "sheath_friction": 0.15,  # liner surface
    "film_friction": 0.20,  # flush fluid and coating hydration
    "sheath_drag_N": 0.20,  # lumen ovality
    "film_viscous_N_s_per_mm": 0.30,  # film amount: the least known constant
    "squeeze_time_s": 0.30,  # lumen clearance (thickness cubed)
    "entrain_length_mm": 0.25,
    "tendon_offset_mm": 0.05,  # lumen placement in the section
    "bend_stiffness_Nm_per_rad": 0.15,  # cover durometer and spine cut
    "section_softening_per_K": 0.20,  # Pebax lot
    "handle_friction_Nm": 0.20,  # knob O-ring squeeze
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
