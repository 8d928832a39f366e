"""Physical constants of the lumped Dahl-friction plant, with units, validated on construction.

Every constant is a field of a frozen dataclass so a unit of the product (``simrig.family``) is one
``dataclasses.replace`` away, and a bad value is refused with a one-line :class:`PlantLoadError`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from simrig.plant import PlantLoadError


def _check_numbers(obj: object, where: str, positive: tuple[str, ...]) -> None:
    """Every field finite; ``positive`` ones > 0, the rest >= 0."""
    for f in fields(obj):  # type: ignore[arg-type]
        value = getattr(obj, f.name)
        name = f"{where}{f.name}"
        if not isinstance(value, int | float) or isinstance(value, bool):
            raise PlantLoadError(f"{name} must be a number, got {value!r}")
        if not math.isfinite(value):
            raise PlantLoadError(f"{name} must be finite, got {value!r}")
        if f.name in positive and value <= 0.0:
            raise PlantLoadError(f"{name} must be > 0, got {value!r}")
        if value < 0.0:
            raise PlantLoadError(f"{name} must be >= 0, got {value!r}")


@dataclass(frozen=True)
class LumpedKnobParams:
    """One knob's tendon pair: pulley, slack toe, handle guide, sheath lumps, bending section."""

    pulley_radius_mm: float = 6.0
    slack_pos_mm: float = 2.6
    """Slack of the tendon drawn in by positive knob rotation (before its toe region)."""
    slack_neg_mm: float = 2.7
    toe_mm: float = 0.45
    """Draw-in over which a slack tendon's stiffness rises from 0 to EA/l (crimp straightening:
    a smooth engagement, not a kink)."""
    tendon_stiffness_N: float = 3500.0
    """Axial stiffness EA of the tendon."""
    sheath_length_m: float = 1.0
    free_length_m: float = 0.03
    """Tendon between pulley and handle guide (holds the slack and its toe)."""
    guide_wrap_deg: float = 60.0
    """Wrap of the tendon over the handle's guide (the first lumped contact)."""
    guide_friction: float = 0.2
    sheath_wrap_deg: float = 420.0
    """Total wrap of the tendon in the straight sheath, shared by the sheath lumps."""
    sheath_friction: float = 0.22
    sheath_drag_N: float = 0.12
    """Tension-independent friction summed over the sheath lumps (lumen preload)."""
    presliding_mm: float = 0.08
    """Dahl presliding length: tendon travel for a contact's friction to build up ~63 % of its
    sliding level after a reversal (bristle compliance of the lumen contact)."""
    tendon_offset_mm: float = 2.6
    """Moment arm of the tendons in the bending section."""
    bend_stiffness_Nm_per_rad: float = 0.0065
    bend_friction_Nm: float = 0.0004
    """Sliding level of the bending section's own hysteresis (links rubbing, cover shear)."""
    bend_presliding_deg: float = 4.0
    """Tip rotation for the bending hysteresis to build ~63 % of its sliding level."""
    handle_friction_Nm: float = 0.012
    """Sliding friction torque of the knob (bearings, brake)."""
    handle_presliding_deg: float = 1.0

    def validated(self, where: str) -> LumpedKnobParams:
        _check_numbers(self, where + ".", _KNOB_POSITIVE)
        return self


_KNOB_POSITIVE = (
    "pulley_radius_mm",
    "toe_mm",
    "tendon_stiffness_N",
    "sheath_length_m",
    "free_length_m",
    "presliding_mm",
    "tendon_offset_mm",
    "bend_stiffness_Nm_per_rad",
    "bend_presliding_deg",
    "handle_presliding_deg",
)

NOMINAL_KNOBS = (
    LumpedKnobParams(),
    LumpedKnobParams(slack_pos_mm=2.7, slack_neg_mm=2.5, sheath_wrap_deg=400.0,
                     tendon_offset_mm=2.55),
)
"""The two knobs of the nominal unit (anterior-posterior, right-left) differ slightly."""


@dataclass(frozen=True)
class LumpedEffects:
    """Switchable unmodelled effects, each in this plant's physics; 0 switches one off."""

    coupling: float = 0.0
    """Scale of the cross-plane coupling (1.0 = nominal, the constants below)."""
    coupling_lumen_angle_deg: float = 10.0
    """Angular misplacement of the tendon lumens: bending the other plane lengthens one tendon's
    path and shortens the other's (shifts the dead zone)."""
    coupling_compression_mm_per_N: float = 0.03
    """Axial compliance of the coil sheath: the other pair's tension compresses it, which
    shortens this pair's path, i.e. adds slack to both tendons (widens the dead zone)."""
    coupling_friction_per_rad: float = 0.6
    """Relative rise of this plane's bending friction per radian bent in the other plane (the
    links press on each other)."""
    viscous_N_s_per_m: float = 0.0
    """Viscous drag of the lubricated lumen per sheath lump (rate dependence; implicit, so stable
    at any step)."""
    tendon_compliance: float = 0.0
    """Extra tendon compliance relative to nominal (1.0 doubles it)."""
    sheath_curvature_deg: float = 0.0
    """Total bend of the sheath path, laid on its distal half: adds wrap there and shortens the
    tendon path by ``lumen_clearance_mm`` per radian (more slack)."""
    lumen_clearance_mm: float = 0.3
    creep_compliance_mm_per_N: float = 0.0
    """Viscoelastic creep of the tendon: slack grows towards this much per newton of tension,
    with time constant ``creep_time_s``, and recovers when unloaded (standard linear solid)."""
    creep_time_s: float = 60.0

    def validated(self) -> LumpedEffects:
        _check_numbers(self, "", ("creep_time_s",))
        return self


UNIT_SCATTER: dict[str, float] = {
    "pulley_radius_mm": 0.02,
    "slack_pos_mm": 0.15,
    "slack_neg_mm": 0.15,
    "toe_mm": 0.20,
    "tendon_stiffness_N": 0.15,
    "sheath_length_m": 0.02,
    "free_length_m": 0.20,
    "guide_wrap_deg": 0.10,
    "guide_friction": 0.15,
    "sheath_wrap_deg": 0.10,
    "sheath_friction": 0.15,
    "sheath_drag_N": 0.20,
    "presliding_mm": 0.20,
    "tendon_offset_mm": 0.05,
    "bend_stiffness_Nm_per_rad": 0.15,
    "bend_friction_Nm": 0.20,
    "bend_presliding_deg": 0.20,
    "handle_friction_Nm": 0.20,
    "handle_presliding_deg": 0.20,
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
