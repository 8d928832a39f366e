"""Constants of the ratestate plant, per knob, with where their values come from.

One knob drives an antagonistic pair of steel wire-rope tendons wound on a drum. Each tendon
runs through the handle (free length), then a polymer-lined lumen along the shaft, split into
``NODES`` contact elements whose wrap follows the shaft's curvature profile, then through the
bending section to the tip. Every contact has its own rate-and-state friction (Dieterich's
ageing law), presliding stiffness and preload drag; the bending section's links rub with a
friction that grows with the tendons' compression of the link stack.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from simrig.plant import PlantLoadError

NODES = 6
"""Contact elements per tendon along the shaft (the chain has 2 NODES + 1 nodes: the tip in
the middle). Six keep a step under the step-cost budget and still let a reversal travel."""


@dataclass(frozen=True)
class RateStateKnobParams:
    """One knob's tendon pair, shaft lumens and bending-section plane."""

    pulley_radius_mm: float = 7.0
    """Drum radius: 14 mm drums in TEE handles (the knob's 90 deg draws 11 mm of tendon)."""
    slack_pos_mm: float = 3.2
    """Tendon slack at the drum when the knob is centred (dead zone ~ slack / radius = 25 deg, less
    the stretch the first contacts take)."""
    slack_neg_mm: float = 3.2
    tendon_stiffness_N: float = 9000.0
    """Axial stiffness EA of a 0.35 mm 7x7 steel wire rope (E_eff ~ 95 GPa on 0.095 mm^2)."""
    free_length_m: float = 0.12
    """Tendon in the handle between drum and shaft, no contact."""
    sheath_length_m: float = 1.0
    """Lined shaft length (TEE probes: ~1 m insertion tube)."""
    bend_length_mm: float = 50.0
    """Bending section length (the tendon's last element)."""
    sheath_wrap_deg: float = 260.0
    """Total lumen wrap along the straight-laid shaft: lumen waviness plus the shaft's own lay;
    distributed by the curvature profile."""
    curve_position: float = 0.6
    """Where along the shaft (0 handle, 1 tip) the shaft's main curve lies (the pharynx)."""
    curve_share: float = 0.45
    """Share of ``sheath_wrap_deg`` concentrated in that curve (the rest uniform)."""
    sheath_friction: float = 0.2
    """Reference friction coefficient mu0 of steel rope on a PTFE liner, dry to boundary
    lubricated (0.05-0.25; the rope's strands make it rougher than a wire)."""
    ageing_b: float = 0.006
    """Dieterich state coefficient b: mu = mu0 + b ln(1 + theta / theta_c); polymer contacts
    age strongly (PTFE static/kinetic ~1.2-1.4 after minutes of dwell)."""
    ageing_dc_mm: float = 0.02
    """Critical slip distance D_c over which the contact's state renews (tens of microns)."""
    ageing_cutoff_s: float = 0.01
    """Cut-off time theta_c of the ageing logarithm (keeps mu finite at theta -> 0)."""
    sheath_drag_N: float = 0.15
    """Preload drag of the lumen on the rope (ovality), summed over the shaft's contacts; the
    capstan amplifies it into the tip's residual bend after a release (~7 deg: the TEE probe's
    plateaus lie 4-5 % of its range apart)."""
    presliding_mm: float = 0.05
    """Tangential travel of a contact before gross slip under the reference load (1 N per
    contact): the liner's shear and the rope's strands slipping on each other. It makes the
    contacts a shear-lag chain, so a reversal reaches the tip gradually (rounded corners)."""
    tendon_offset_mm: float = 4.2
    """Lumen offset from the bending section's neutral axis (12 mm TEE tip)."""
    bend_stiffness_Nm_per_rad: float = 0.022
    """Bending stiffness of this plane (cover, links and the other plane's tendons)."""
    bend_lumen_friction: float = 0.05
    """Friction coefficient of the tendon over the bending section's bend (a PTFE-lined coil
    lumen in the links; wrap = the section's total bend, both planes)."""
    link_friction: float = 0.01
    """Link-stack friction: moment / (offset x summed tension of the pair): the tendons
    compress the stack of links, which rub at their pivots."""
    link_drag_Nm: float = 0.001
    """Moment the bending section's cover and links need to start bending at all (internal
    friction of the cover, independent of the tendons' load)."""
    handle_friction_Nm: float = 0.005
    """Knob shaft bearing and seal (Coulomb, smoothed over ``handle_speed_deg_s``)."""
    handle_speed_deg_s: float = 1.0

    def check(self) -> None:
        """Refuse non-physical constants (one clear line each)."""
        positive = ("pulley_radius_mm", "tendon_stiffness_N", "sheath_length_m",
                    "bend_length_mm", "tendon_offset_mm", "bend_stiffness_Nm_per_rad",
                    "ageing_dc_mm", "ageing_cutoff_s", "presliding_mm", "handle_speed_deg_s")
        for name in positive:
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise PlantLoadError(f"ratestate knob constant {name} must be > 0, got {value!r}")
        for name in ("slack_pos_mm", "slack_neg_mm", "free_length_m", "sheath_wrap_deg",
                     "sheath_friction", "ageing_b", "sheath_drag_N", "bend_lumen_friction",
                     "link_friction", "link_drag_Nm",
                     "handle_friction_Nm"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise PlantLoadError(f"ratestate knob constant {name} must be >= 0, got {value!r}")
        if not 0.0 <= self.curve_position <= 1.0 or not 0.0 <= self.curve_share <= 1.0:
            raise PlantLoadError("ratestate curve_position and curve_share must be in [0, 1]")


NOMINAL_KNOBS: tuple[RateStateKnobParams, RateStateKnobParams] = (
    RateStateKnobParams(),
    RateStateKnobParams(tendon_offset_mm=4.0, bend_stiffness_Nm_per_rad=0.020,
                        slack_pos_mm=3.1, slack_neg_mm=3.1, curve_position=0.55),
)
"""The right-left plane (knob 2) sits on lumens a little closer to the axis and bends a little
easier (a flattened section), with slightly less slack set at assembly."""


def knob_params(knobs: Sequence[Mapping[str, Any] | RateStateKnobParams] | None
                ) -> tuple[RateStateKnobParams, RateStateKnobParams]:
    """The two knobs' constants: the nominal ones overridden by ``knobs`` (dicts or
    dataclasses), checked."""
    if knobs is None:
        return NOMINAL_KNOBS
    if len(knobs) != 2:
        raise PlantLoadError(f"ratestate takes 2 knobs, got {len(knobs)}")
    names = {f.name for f in dataclasses.fields(RateStateKnobParams)}
    out = []
    for nominal, given in zip(NOMINAL_KNOBS, knobs, strict=True):
        if isinstance(given, RateStateKnobParams):
            params = given
        else:
            unknown = sorted(set(given) - names)
            if unknown:
                raise PlantLoadError(f"unknown ratestate knob constants: {', '.join(unknown)}")
            params = dataclasses.replace(nominal, **{k: float(v) for k, v in given.items()})
        params.check()
        out.append(params)
    return out[0], out[1]


UNIT_SCATTER: dict[str, float] = {
    "pulley_radius_mm": 0.02,  # machined drum
    "slack_pos_mm": 0.15,  # tendon wound and crimped by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # wire-rope lot (steel: less than polymer)
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "bend_length_mm": 0.03,  # link stack cut to length
    "sheath_wrap_deg": 0.15,  # lumen waviness of the extrusion and the shaft's lay
    "curve_position": 0.10,  # where the shaft's set curve lies (coiled in its box)
    "curve_share": 0.20,
    "sheath_friction": 0.15,  # liner and rope surface, lubricant left from assembly
    "ageing_b": 0.30,  # polymer contact ageing: liner lot, the least known constant
    "ageing_dc_mm": 0.30,  # contact asperity size
    "sheath_drag_N": 0.25,  # lumen ovality
    "presliding_mm": 0.20,  # liner shear compliance
    "tendon_offset_mm": 0.05,  # lumen placement in the links
    "bend_stiffness_Nm_per_rad": 0.15,  # cover durometer and links
    "bend_lumen_friction": 0.20,  # coil lumen in the links
    "link_friction": 0.25,  # link pivots: moulding and grease
    "link_drag_Nm": 0.25,  # cover's internal friction
    "handle_friction_Nm": 0.20,  # knob bearing and seal
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
