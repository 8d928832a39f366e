"""Constants of the capstan plant: per-knob parameters and the optional unmodelled effects.

Each dataclass validates itself (``validated``) so a bad plant file fails with one line naming
the field; :mod:`simrig.plants.capstan.tendon_sheath` builds the plant from them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from simrig.plant import PlantLoadError


@dataclass(frozen=True)
class KnobParams:
    """Mechanical constants of one knob's tendon pair (units in the names)."""

    pulley_radius_mm: float = 6.0
    slack_pos_mm: float = 2.4
    """Slack of the tendon pulled by positive knob rotation."""
    slack_neg_mm: float = 2.58
    tendon_offset_mm: float = 3.46
    """Moment arm of the tendons in the bending section."""
    tendon_stiffness_N: float = 12000.0
    """Axial stiffness EA of the tendon (a steel wire of about 0.3 mm; with a compliant tendon,
    e.g. 6000 N, stretch takes a larger share of the draw-in while loading than while releasing
    and the tip releases steeper than it loads, unlike the real TEE probe: docs/plant.md)."""
    sheath_length_m: float = 1.0
    free_length_m: float = 0.01
    """Tendon length between pulley and sheath entry (no friction)."""
    sheath_friction: float = 0.35
    """Coulomb friction coefficient tendon/sheath."""
    sheath_wrap_deg: float = 480.0
    """Total wrap angle of the tendon in the (straight) sheath: coil helix and lumen contact."""
    routing_wrap_deg: float = 0.0
    """Wrap of the tendon over guide pins in the handle, right after the pulley. The default
    handle runs the tendon straight from the pulley into the sheath; a routed handle (e.g. 360)
    isolates the knob from the sheath, so the motor current no longer shows the backlash
    (docs/plant.md, "Handle routing")."""
    routing_friction: float = 0.25
    """Friction coefficient on the handle guide pins."""
    sheath_drag_N: float = 0.15
    """Tension-independent friction summed over the sheath (preload of the coil sheath, tendon
    bending stiffness in its lumen); it traps some tension when released (residual bend)."""
    bend_stiffness_Nm_per_rad: float = 0.0065
    bend_friction_Nm: float = 0.0006
    """Mean Coulomb friction moment of the bending joints (spread 0.4x..1.6x over the joints)."""
    bend_stiction_ratio: float = 1.0
    """Static over kinetic friction of the bending joints (>= 1; 1 = off): with more, a joint
    breaks loose with a small jump of the tip and of the tendon tension (stick-slip)."""
    handle_friction_Nm: float = 0.012
    """Kinetic friction torque of the knob itself (bearings, friction brake)."""
    handle_stiction_Nm: float = 0.04
    """Friction torque of the knob when it starts to slide after a reversal or a stop."""
    handle_slip_deg: float = 3.0
    """Knob travel over which the handle friction falls from static to kinetic (the friction
    contact renews itself over a characteristic slip distance, as in rate-and-state friction)."""

    def validated(self, where: str) -> KnobParams:
        for f in fields(self):
            value = getattr(self, f.name)
            if not isinstance(value, int | float) or isinstance(value, bool):
                raise PlantLoadError(f"{where}.{f.name} must be a number, got {value!r}")
            if not math.isfinite(value):
                raise PlantLoadError(f"{where}.{f.name} must be finite, got {value!r}")
        positive = (
            "pulley_radius_mm",
            "tendon_offset_mm",
            "tendon_stiffness_N",
            "sheath_length_m",
            "bend_stiffness_Nm_per_rad",
            "handle_slip_deg",
        )
        for name in positive:
            if getattr(self, name) <= 0.0:
                raise PlantLoadError(f"{where}.{name} must be > 0, got {getattr(self, name)!r}")
        if self.bend_stiction_ratio < 1.0:
            raise PlantLoadError(
                f"{where}.bend_stiction_ratio must be >= 1, got {self.bend_stiction_ratio!r}"
            )
        for f in fields(self):
            if f.name not in positive and getattr(self, f.name) < 0.0:
                raise PlantLoadError(
                    f"{where}.{f.name} must be >= 0, got {getattr(self, f.name)!r}"
                )
        return self


# The anterior-posterior and right-left knobs of one catheter differ slightly.
DEFAULT_KNOBS = (
    KnobParams(),
    KnobParams(slack_pos_mm=2.58, slack_neg_mm=2.34, sheath_wrap_deg=450.0, tendon_offset_mm=3.40),
)


@dataclass(frozen=True)
class Effects:
    """Strength of the switchable unmodelled effects; 0 switches an effect off."""

    coupling: float = 0.0
    """Scale of the cross-knob coupling (1.0 = nominal, see the two constants below)."""
    coupling_tendon_twist_deg: float = 8.0
    """Angular misplacement of the tendons from the ideal orthogonal lumens: bending the other
    plane changes their path length in opposite senses, shifting the dead zone linearly."""
    coupling_shortening_mm_per_rad2: float = 0.45
    """Axial shortening of the bending section when bent in the other plane (adds slack to both
    tendons, widening the dead zone quadratically)."""
    rate_dependence: float = 0.0
    """Relative rise of the sheath friction per ``rate_reference_deg_s`` of knob speed
    (viscous drag of the lubricated sheath; the handle guides are unaffected)."""
    rate_reference_deg_s: float = 100.0
    tendon_compliance: float = 0.0
    """Extra tendon compliance relative to the nominal one (1.0 doubles it)."""
    sheath_curvature_deg: float = 0.0
    """Total bend of the sheath path (e.g. 180 for a U loop): adds wrap angle and slack."""
    lumen_clearance_mm: float = 0.35
    """Radial play of the tendon in its lumen; a curved sheath shortens the path by this much
    per radian of curvature."""
    creep_mm_per_N_s: float = 0.0
    """Tendon creep: slack grows by this much per newton of tension per second."""

    def validated(self) -> Effects:
        for f in fields(self):
            value = getattr(self, f.name)
            if not isinstance(value, int | float) or isinstance(value, bool):
                raise PlantLoadError(f"{f.name} must be a number, got {value!r}")
            if not math.isfinite(value) or value < 0.0:
                raise PlantLoadError(f"{f.name} must be finite and >= 0, got {value!r}")
        if self.rate_reference_deg_s <= 0.0:
            raise PlantLoadError(
                f"rate_reference_deg_s must be > 0, got {self.rate_reference_deg_s!r}"
            )
        return self


UNIT_SCATTER: dict[str, float] = {
    "pulley_radius_mm": 0.02,  # machined part
    "slack_pos_mm": 0.15,  # assembly: tendon cut and crimped by hand
    "slack_neg_mm": 0.15,
    "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
    "tendon_stiffness_N": 0.15,  # tendon lot (EA)
    "sheath_length_m": 0.02,
    "free_length_m": 0.20,
    "sheath_friction": 0.15,  # coating, lubricant
    "sheath_wrap_deg": 0.10,  # coil pitch
    "routing_wrap_deg": 0.10,
    "routing_friction": 0.15,
    "sheath_drag_N": 0.20,
    "bend_stiffness_Nm_per_rad": 0.15,  # polymer cover, links
    "bend_friction_Nm": 0.20,
    "handle_friction_Nm": 0.20,  # knob bearing / brake setting
    "handle_stiction_Nm": 0.20,
    "handle_slip_deg": 0.20,
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
