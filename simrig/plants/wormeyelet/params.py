"""Constants of the wormeyelet plant, per knob, with where their values come from.

The handle turns each knob's drum through a worm stage, so its constants are the worm's (lead
angle, mesh friction, flank play) and the drum's; the ropes are stainless 7x7 wire rope; the
bending section is a spring backbone threaded through spacer disks whose eyelets the ropes rub.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class WormEyeletKnob:
    """One knob's drive train, ropes and bending plane."""

    worm_ratio: float = 3.0
    """Knob (worm) turns per drum (wheel) turn: a 4-start worm on a 12-tooth wheel."""
    worm_lead_deg: float = 12.0
    """Lead angle of the worm thread (multi-start worms: 10-25 deg; below the friction angle the
    stage locks against back-driving)."""
    worm_friction: float = 0.08
    """Sliding friction of the worm flank on the wheel (steel on a glass-filled polyamide wheel,
    greased: 0.05-0.12)."""
    worm_play_deg: float = 1.2
    """Flank play of the wheel on the worm, in wheel degrees (moulded wheel: 0.5-2 deg)."""
    drum_radius_mm: float = 18.0
    """Rope drum on the wheel."""
    slack_pos_mm: float = 2.55
    """Slack of the "+" rope at assembly (crimped by hand)."""
    slack_neg_mm: float = 2.65
    tendon_stiffness_N: float = 22000.0
    """Axial stiffness EA of a 0.4 mm 1x19 stainless rope (wire E 190 GPa, fill and lay ~0.9)."""
    sheath_length_m: float = 1.0
    """Shaft length from the handle to the bending section (TEE probes: ~1 m)."""
    section_length_mm: float = 60.0
    """Bending section (TEE: 50-70 mm)."""
    contact_fraction: float = 0.55
    """Where along the shaft the lumen friction acts (its centroid, from the handle)."""
    sheath_friction: float = 0.18
    """Rope on the PTFE lumen liner (0.1-0.25)."""
    sheath_wrap_deg: float = 600.0
    """Wrap of the rope in the straight shaft (the lumen's helix and the shaft's sag)."""
    sheath_drag_N: float = 0.4
    """Tension-independent lumen drag (the liner's preload on the rope)."""
    tendon_offset_mm: float = 3.2
    """Rope's distance from the backbone in the section (eyelet radius)."""
    section_stiffness_Nmm_per_rad: float = 22.0
    """Bending stiffness over length of the backbone spring and cover, EI/L."""
    eyelet_friction: float = 0.20
    """Rope on the spacer disks' eyelets (stainless on stainless, dry: 0.15-0.3)."""
    disk_friction_N: float = 0.5
    """Spacer disks sliding along the cover sleeve as the section bends, as a rope tension."""
    cross_wrap: float = 0.5
    """Share of the other plane's bend that the eyelets add to this rope's wrap."""
    handle_friction_Nm: float = 0.004
    """Worm shaft seal and bearings, at the knob."""
    damper_Nm_s_per_rad: float = 0.02
    """Silicone-oil rotary damper on the knob shaft, zero-speed viscous coefficient."""
    damper_thinning_rad_s: float = 1.5
    """Knob speed at which the damper's oil has thinned to half its zero-shear torque ratio."""

    def __post_init__(self) -> None:
        positive = ("worm_ratio", "worm_lead_deg", "drum_radius_mm", "tendon_stiffness_N",
                    "sheath_length_m", "section_length_mm", "tendon_offset_mm",
                    "section_stiffness_Nmm_per_rad", "eyelet_friction", "damper_thinning_rad_s")
        for name in positive:
            if not getattr(self, name) > 0.0:
                raise ValueError(f"wormeyelet {name} must be > 0, got {getattr(self, name)!r}")
        for name in ("worm_friction", "worm_play_deg", "slack_pos_mm", "slack_neg_mm",
                     "sheath_friction", "sheath_wrap_deg", "sheath_drag_N", "cross_wrap",
                     "disk_friction_N",
                     "handle_friction_Nm", "damper_Nm_s_per_rad"):
            if not getattr(self, name) >= 0.0:
                raise ValueError(f"wormeyelet {name} must be >= 0, got {getattr(self, name)!r}")
        if not 0.0 < self.contact_fraction < 1.0:
            raise ValueError(f"wormeyelet contact_fraction must be in (0, 1), "
                             f"got {self.contact_fraction!r}")
        if not self.worm_lead_deg < 60.0:
            raise ValueError("wormeyelet worm_lead_deg must be < 60")

    @property
    def drive_efficiency(self) -> float:
        """Worm driving the wheel: tan(lead) / tan(lead + friction angle)."""
        lead = math.radians(self.worm_lead_deg)
        return math.tan(lead) / math.tan(lead + math.atan(self.worm_friction))

    @property
    def back_efficiency(self) -> float:
        """Wheel driving the worm: tan(lead - friction angle) / tan(lead); <= 0 self-locks."""
        lead = math.radians(self.worm_lead_deg)
        return math.tan(lead - math.atan(self.worm_friction)) / math.tan(lead)


NOMINAL_KNOBS: tuple[WormEyeletKnob, WormEyeletKnob] = (
    WormEyeletKnob(),
    WormEyeletKnob(slack_pos_mm=2.65, slack_neg_mm=2.45, section_stiffness_Nmm_per_rad=19.0,
                   sheath_wrap_deg=560.0),
)
"""Right-left (knob 2) is softer (the section's cover is thinner at the sides) and its lumens
run straighter."""


def knobs_from(knobs: Sequence[Mapping[str, Any]] | None) -> tuple[WormEyeletKnob, ...]:
    """Both knobs' constants: the nominal ones with the given overrides, checked."""
    if knobs is None:
        return NOMINAL_KNOBS
    if len(knobs) != 2:
        raise ValueError(f"wormeyelet takes 2 knobs, got {len(knobs)}")
    names = {f.name for f in dataclasses.fields(WormEyeletKnob)}
    out = []
    for nominal, given in zip(NOMINAL_KNOBS, knobs, strict=True):
        unknown = sorted(set(given) - names)
        if unknown:
            raise ValueError(f"unknown wormeyelet knob constants: {', '.join(unknown)}")
        out.append(dataclasses.replace(nominal, **{k: float(v) for k, v in given.items()}))
    return tuple(out)


UNIT_SCATTER: dict[str, float] = {
    "worm_lead_deg": 0.03,  # ground worm thread
    "worm_friction": 0.25,  # grease left from assembly, wheel moulding
    "worm_play_deg": 0.30,  # wheel tooth thickness and centre distance: a tolerance stack
    "drum_radius_mm": 0.02,  # moulded drum
    "slack_pos_mm": 0.15,  # rope crimped to the drum by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # rope lot (EA)
    "contact_fraction": 0.10,  # where the shaft's sag puts the rope on the liner
    "sheath_friction": 0.15,  # liner batch, lubricant
    "sheath_wrap_deg": 0.10,  # lumen helix pitch
    "sheath_drag_N": 0.25,  # liner preload
    "tendon_offset_mm": 0.05,  # eyelet placement in the disks
    "section_stiffness_Nmm_per_rad": 0.15,  # backbone spring and cover
    "eyelet_friction": 0.20,  # eyelet finish (deburred by hand)
    "disk_friction_N": 0.25,  # disk fit in the sleeve
    "cross_wrap": 0.20,
    "handle_friction_Nm": 0.20,  # worm shaft seal squeeze
    "damper_Nm_s_per_rad": 0.20,  # oil fill and gap of the damper
    "damper_thinning_rad_s": 0.20,
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
