"""Constants of the notchclutch plant, one set per knob (plane), with where they come from.

Lengths in mm unless the name says otherwise, angles in degrees at the interface, forces in N,
moments in N mm. The nominal values are the product's design; ``UNIT_SCATTER`` below says how
much each scatters from unit to unit.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from simrig.plant import PlantLoadError


@dataclass(frozen=True)
class NotchClutchKnob:
    """One knob, its slip clutch, its pair of aramid tendons and its plane of the section."""

    # handle: knob -> slip clutch -> drum
    drum_radius_mm: float = 8.0
    """Tendon drum on the clutch's output (TEE handles: wheels of 20-30 mm)."""
    clutch_capacity_Nmm: float = 380.0
    """Breakaway torque of the friction clutch (wave-spring preload x plate friction x radius):
    a torque limiter that protects the tendons at the end of the range."""
    clutch_kinetic_ratio: float = 0.85
    """Slipping torque over breakaway torque of the clutch plates (dry friction facings)."""
    handle_friction_Nm: float = 0.004
    """Knob shaft seal before the clutch (felt by the motor whatever the clutch does)."""
    # aramid tendons
    slack_pos_mm: float = 3.3
    """Slack of the tendon that bends the tip positively (assembly: braid cut and knotted)."""
    slack_neg_mm: float = 3.3
    toe_mm: float = 0.4
    """Crimp of the aramid braid: force rises with the square of the stretch over the toe."""
    tendon_stiffness_N: float = 9000.0
    """EA of the braid (Kevlar 49, ~0.11 mm^2 of fibre, E ~ 80 GPa)."""
    rate_stiffening: float = 0.05
    """Aramid's dynamic modulus rises by this per e-fold of strain rate above the reference."""
    reference_strain_rate_per_s: float = 1e-3
    sheath_length_m: float = 0.3
    """Tendon length from the drum to the lumped lumen contact: the wrap sits mostly in the
    handle's routing and the pharyngeal curve, the proximal third of the shaft."""
    free_length_m: float = 0.75
    """Tendon length from the lumen contact to its anchor in the tip (rest of the shaft and the
    section)."""
    tendon_offset_mm: float = 4.2
    """Lumen radius in the tube (moment arm of the tendon about the section's neutral axis)."""
    # hydrophilic-coated liner: mixed lubrication
    sheath_friction: float = 0.11
    """Boundary friction of the aramid braid on the soaked hydrophilic liner."""
    dry_friction_ratio: float = 1.5
    """Friction of the liner at insertion over soaked (coating not yet hydrated)."""
    soak_time_s: float = 40.0
    """Time constant of the coating's hydration after insertion."""
    stribeck_rise: float = 0.1
    """Breakaway friction above the boundary level (mixed lubrication at low speed)."""
    stribeck_speed_mm_s: float = 0.8
    """Sliding speed at which the film carries (1/e of the rise is left)."""
    film_time_s: float = 0.15
    """Time for the lubricant film to build or collapse after the speed changes."""
    sheath_wrap_deg: float = 300.0
    """Wrap of the lumen along the shaft (the oesophageal curve and the handle's routing)."""
    bend_wrap_share: float = 0.1
    """Share of the section's total bend (both planes) that adds to the tendons' wrap."""
    sheath_drag_N: float = 0.1
    """Tension-independent drag of the braid in the soaked liner: the swollen hydrogel squeezes
    the braid in its lumen (the fit's normal force)."""
    dry_drag_ratio: float = 0.6
    """Drag at insertion over soaked (the coating swells as it hydrates)."""
    # laser-cut steel section
    bend_stiffness_Nmm_per_rad: float = 30.0
    """Notched stainless tube plus its polymer cover, per plane."""
    notch_close_deg: float = 135.0
    """Total bend (both planes) at which the notches on the concave side start to touch."""
    notch_close_width_deg: float = 12.0
    """Spread of notch closure along the section (the notches close one after another)."""
    notch_stiffening: float = 6.0
    """Stiffness added by closed notches, in units of the open tube's stiffness."""
    # tip on the oesophageal wall
    tissue_friction_Nmm: float = 4.0
    """Friction moment of the tip's face sliding on the mucosa at rest contact."""
    tissue_friction_ratio: float = 0.05
    """Friction moment per elastic moment of the bend: the wall presses harder the more the tip
    bends into it (mucosa, mu ~ 0.3 on a wet steel-polymer face)."""

    def validate(self) -> None:
        for name in ("drum_radius_mm", "clutch_capacity_Nmm", "tendon_stiffness_N",
                     "sheath_length_m", "free_length_m", "tendon_offset_mm",
                     "bend_stiffness_Nmm_per_rad", "soak_time_s", "stribeck_speed_mm_s",
                     "film_time_s", "toe_mm", "notch_close_width_deg",
                     "reference_strain_rate_per_s"):
            if not getattr(self, name) > 0.0:
                raise PlantLoadError(f"notchclutch: {name} must be > 0")
        for name in ("slack_pos_mm", "slack_neg_mm", "sheath_friction", "sheath_wrap_deg",
                     "bend_wrap_share", "sheath_drag_N", "dry_drag_ratio", "handle_friction_Nm",
                     "stribeck_rise",
                     "rate_stiffening", "notch_stiffening", "tissue_friction_Nmm",
                     "notch_close_deg"):
            if not getattr(self, name) >= 0.0:
                raise PlantLoadError(f"notchclutch: {name} must be >= 0")
        if not 0.0 < self.clutch_kinetic_ratio <= 1.0:
            raise PlantLoadError("notchclutch: clutch_kinetic_ratio must be in (0, 1]")
        if not self.dry_friction_ratio >= 1.0:
            raise PlantLoadError("notchclutch: dry_friction_ratio must be >= 1")
        if not 0.0 <= self.tissue_friction_ratio < 1.0:
            raise PlantLoadError("notchclutch: tissue_friction_ratio must be in [0, 1)")
        for v in dataclasses.astuple(self):
            if not math.isfinite(v):
                raise PlantLoadError("notchclutch: every constant must be finite")


NOMINAL_KNOBS = (NotchClutchKnob(),
                 NotchClutchKnob(bend_stiffness_Nmm_per_rad=26.0, tendon_offset_mm=4.0,
                                 slack_pos_mm=3.5, slack_neg_mm=3.5))
"""Anterior-posterior, then right-left (the right-left plane is softer and looser, as on TEE
probes)."""

KNOB_FIELDS = frozenset(f.name for f in dataclasses.fields(NotchClutchKnob))


def knobs_from(knobs: Sequence[Mapping[str, Any] | NotchClutchKnob] | None
               ) -> tuple[NotchClutchKnob, NotchClutchKnob]:
    """Both knobs' constants from mappings (missing names take the nominal value)."""
    if knobs is None:
        return NOMINAL_KNOBS
    if len(knobs) != 2:
        raise PlantLoadError(f"notchclutch takes 2 knobs, got {len(knobs)}")
    out: list[NotchClutchKnob] = []
    for nominal, given in zip(NOMINAL_KNOBS, knobs, strict=True):
        if isinstance(given, NotchClutchKnob):
            knob = given
        else:
            unknown = sorted(set(given) - KNOB_FIELDS)
            if unknown:
                raise PlantLoadError(f"unknown notchclutch knob constants: {', '.join(unknown)}")
            try:
                knob = dataclasses.replace(nominal, **{k: float(v) for k, v in given.items()})
            except (TypeError, ValueError) as exc:
                raise PlantLoadError(f"notchclutch knob constants: {exc}") from None
        knob.validate()
        out.append(knob)
    return out[0], out[1]


UNIT_SCATTER: dict[str, float] = {
    "drum_radius_mm": 0.02,  # moulded drum
    "clutch_capacity_Nmm": 0.15,  # wave-spring preload and facing friction of the clutch
    "clutch_kinetic_ratio": 0.05,
    "handle_friction_Nm": 0.20,  # knob seal
    "slack_pos_mm": 0.15,  # braid cut and knotted by hand
    "slack_neg_mm": 0.15,
    "toe_mm": 0.20,  # braid crimp of the lot
    "tendon_stiffness_N": 0.10,  # aramid lot
    "rate_stiffening": 0.20,
    "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
    "sheath_friction": 0.15,  # coating thickness and cure
    "dry_friction_ratio": 0.10,
    "soak_time_s": 0.30,  # coating thickness
    "stribeck_rise": 0.20,
    "sheath_wrap_deg": 0.10,  # routing in the handle
    "sheath_drag_N": 0.20,  # lumen fit
    "bend_stiffness_Nmm_per_rad": 0.15,  # laser cut, cover durometer
    "notch_close_deg": 0.05,  # notch width of the cut
    "tissue_friction_Nmm": 0.25,  # the patient's mucosa, the probe's position
    "tissue_friction_ratio": 0.25,
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
