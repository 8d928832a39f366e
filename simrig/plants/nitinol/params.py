"""Constants of the nitinol plant, each with the source of its magnitude, and their checks.

One knob's entry (:class:`NitinolKnobParams`) holds its tendon pair, its lumen offsets and its
plane's cover stiffness. The bending section's superelastic NiTi tube is one part shared by both
planes: its constants appear in both knobs' entries (so the family's per-knob scatter draws them)
and the plant uses their mean (:func:`backbone`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from simrig.plant import PlantLoadError

REFERENCE_TEMPERATURE_C = 37.0
"""The plateau stresses below are quoted at body temperature (ASTM F2516 tests at 37 C)."""


@dataclass(frozen=True)
class NitinolKnobParams:
    """One knob: its drum, its two tendons, their lumen contact and its plane of the tip."""

    pulley_radius_mm: float = 5.0
    """Handle drum; 5-8 mm on steerable-catheter and TEE handles (knob torques of 0.1-0.2 Nm at
    the paper's and the TEE data's currents)."""
    slack_pos_mm: float = 2.2
    """Tendon length beyond its path at assembly (crimped by hand): sets the dead zone, 2.2 mm on
    a 5 mm drum is 25 knob degrees (the paper's and TEE dead zones: 20-30 deg)."""
    slack_neg_mm: float = 2.2
    tendon_stiffness_N: float = 16000.0
    """EA of a 0.5-0.55 mm 7x7 stainless wire rope (metallic area ~0.15 mm^2 at the ~110 GPa
    effective modulus of a stranded rope)."""
    free_length_m: float = 0.15
    """Tendon inside the handle, drum to sheath entry."""
    sheath_length_m: float = 1.0
    """Insertion tube of a TEE probe: about 1 m."""
    contact_fraction: float = 0.5
    """Where along the sheath the lumped lumen contact sits: the centroid of a uniformly
    distributed contact (not scattered)."""
    sheath_wrap_deg: float = 250.0
    """Total turning of the lumen along the insertion tube laid through a pharynx and oesophagus
    model (90-180 deg of curve, plus the lumen's own helix and meander: 1-2 turns in all)."""
    sheath_friction: float = 0.09
    """Boundary friction of stainless rope on a PTFE liner with silicone lubricant left from
    assembly (0.04-0.1 for lubricated PTFE/steel pairs; dry 0.1-0.2)."""
    sheath_drag_N: float = 0.4
    """Tension-independent drag of the liner on the rope (lumen ovality preload)."""
    film_damping_N_s_per_mm: float = 0.15
    """Couette shear of the lubricant film: viscosity ~1 Pa s (1000 cSt silicone oil) over
    pi x 0.45 mm x 1 m of rope at a 5-10 um film gives 0.1-0.2 N per mm/s."""
    tendon_offset_mm: float = 3.1
    """Lumen offset from the neutral axis on the positive side of this plane (TEE bending
    sections: 10-14 mm diameter, lumens at 3-5 mm)."""
    offset_ratio_neg: float = 0.9
    """The negative side's lumen offset over the positive side's: a bending section moulded
    around an off-centre working channel puts one lumen of the pair closer to the axis."""
    bend_length_mm: float = 50.0
    """Steerable section of a TEE probe: 40-60 mm."""
    cover_stiffness_Nm_per_rad: float = 0.007
    """Links and silicone cover of the bending section in this plane (EI/L of a 12 mm sleeve of
    0.5 mm wall at E 2-5 MPa: 0.005-0.015 Nm/rad); a flat-wire braid makes the planes differ
    by 10-30 %."""
    handle_friction_Nm: float = 0.015
    """Knob O-ring and bearing: the flat torque in the dead zone (the paper's current in phase 1
    sits at 10-20 % of its peak)."""
    handle_presliding_deg: float = 1.0
    """Knob rotation before the O-ring slides (its elastic shear)."""
    backbone_od_mm: float = 2.5
    """Superelastic NiTi spine tube along the bending section (laser-cut spines of steerable
    catheters and endoscopes: 1.5-4 mm, walls 0.1-0.3 mm)."""
    backbone_id_mm: float = 2.3
    slot_stiffness_factor: float = 0.2
    """Share of the plain tube's bending stiffness the laser-cut slots leave (10-40 % for the
    interlocking and staggered cuts of steerable spines); the struts strain as the tube would."""
    austenite_modulus_GPa: float = 55.0
    """Austenite modulus of superelastic NiTi: 40-75 GPa (ASTM F2516 reports 50-70)."""
    upper_plateau_MPa: float = 480.0
    """Loading (austenite -> martensite) plateau at 37 C: 400-550 MPa for medical wire/tube."""
    lower_plateau_MPa: float = 150.0
    """Unloading (martensite -> austenite) plateau at 37 C: 150-300 MPa (a wide flag: the
    tube's loop is large)."""
    transformation_strain: float = 0.045
    """Plateau length in strain: 4-6 %."""
    plateau_hardening: float = 0.1
    """Rise of the plateau moment per unit transformed fraction, over its onset moment: in
    bending the moment keeps rising on the plateau as the transformed shell grows inward
    (a tube's plastic-to-elastic section moduli differ by 5-30 %)."""
    clausius_clapeyron_MPa_per_K: float = 6.5
    """dSigma/dT of both plateaus: 5-8 MPa/K for NiTi (Clausius-Clapeyron)."""

    def check(self, knob: int) -> None:
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if not (isinstance(v, (int, float)) and math.isfinite(v)):
                raise PlantLoadError(f"knob {knob}: {f.name} must be finite, got {v!r}")
            if v < 0.0 or (v == 0.0 and f.name not in _MAY_BE_ZERO):
                raise PlantLoadError(f"knob {knob}: {f.name} must be finite and "
                                     f"{'>= 0' if f.name in _MAY_BE_ZERO else '> 0'}, got {v!r}")
        if not (self.contact_fraction < 1.0 and self.slot_stiffness_factor <= 1.0):
            raise PlantLoadError(f"knob {knob}: contact_fraction must be in (0, 1) and "
                                 "slot_stiffness_factor in (0, 1]")
        if not self.backbone_id_mm < self.backbone_od_mm:
            raise PlantLoadError(f"knob {knob}: backbone_id_mm must be below backbone_od_mm")
        if not self.lower_plateau_MPa < self.upper_plateau_MPa:
            raise PlantLoadError(f"knob {knob}: lower_plateau_MPa must be below "
                                 "upper_plateau_MPa (the loop's flag)")
        if not self.sheath_friction * math.radians(self.sheath_wrap_deg + 180.0) < 1.6:
            raise PlantLoadError(f"knob {knob}: sheath_friction x wrap is beyond the lumped "
                                 "contact's range (mu x wrap < 1.6 rad, leaving room for bends)")


_MAY_BE_ZERO = frozenset({"slack_pos_mm", "slack_neg_mm", "sheath_wrap_deg", "sheath_friction",
                          "sheath_drag_N", "film_damping_N_s_per_mm", "handle_friction_Nm",
                          "clausius_clapeyron_MPa_per_K", "plateau_hardening"})

NOMINAL_KNOBS = (
    NitinolKnobParams(),
    NitinolKnobParams(cover_stiffness_Nm_per_rad=0.0085, offset_ratio_neg=0.92),
)
"""Knob 2's plane is the stiffer one (the braid's flat wires lie across it) and its lumens are
nearer to symmetric."""


@dataclass(frozen=True)
class Backbone:
    """The NiTi tube at the moment level: elastic austenite, flag-shaped transformation."""

    stiffness_Nm_per_rad: float
    """EI/L of the austenite tube."""
    forward_Nm: float
    """Moment at which the outer fibre starts turning to martensite (upper plateau)."""
    reverse_Nm: float
    """Moment at which it turns back (lower plateau); > 0: the tube is superelastic."""
    hardening_Nm: float
    """Rise of both plateau moments per unit transformed fraction."""
    transformation_rad: float
    """Bend the section gains when fully transformed (outer-fibre strain over its radius)."""


def backbone(knobs: Sequence[NitinolKnobParams], temperature_C: float) -> Backbone:
    """The shared tube from the mean of both knobs' entries, at ``temperature_C``."""
    def mean(name: str) -> float:
        return sum(float(getattr(k, name)) for k in knobs) / len(knobs)

    od_m, id_m = mean("backbone_od_mm") * 1e-3, mean("backbone_id_mm") * 1e-3
    length_m = mean("bend_length_mm") * 1e-3
    inertia_m4 = math.pi / 64.0 * (od_m ** 4 - id_m ** 4) * mean("slot_stiffness_factor")
    fibre_m = od_m / 2.0
    shift_MPa = mean("clausius_clapeyron_MPa_per_K") * (temperature_C - REFERENCE_TEMPERATURE_C)
    upper_Pa = (mean("upper_plateau_MPa") + shift_MPa) * 1e6
    lower_Pa = (mean("lower_plateau_MPa") + shift_MPa) * 1e6
    if not lower_Pa > 0.0:
        raise PlantLoadError(f"the NiTi backbone is not superelastic at {temperature_C:g} C "
                             "(its lower plateau is <= 0 there): raise temperature_C")
    forward = upper_Pa * inertia_m4 / fibre_m
    return Backbone(
        stiffness_Nm_per_rad=mean("austenite_modulus_GPa") * 1e9 * inertia_m4 / length_m,
        forward_Nm=forward,
        reverse_Nm=lower_Pa * inertia_m4 / fibre_m,
        hardening_Nm=mean("plateau_hardening") * forward,
        transformation_rad=mean("transformation_strain") * length_m / fibre_m,
    )


def knob_params(overrides: Sequence[Mapping[str, Any]] | None) -> tuple[NitinolKnobParams, ...]:
    """Both knobs' constants: the nominal ones with ``overrides`` applied, checked."""
    if overrides is None:
        overrides = [{}, {}]
    if isinstance(overrides, (str, bytes)) or not isinstance(overrides, Sequence) or len(
            overrides) != 2:
        raise PlantLoadError("knobs must be a list of 2 mappings of knob constants")
    known = {f.name for f in dataclasses.fields(NitinolKnobParams)}
    out = []
    for i, (nominal, given) in enumerate(zip(NOMINAL_KNOBS, overrides, strict=True)):
        if not isinstance(given, Mapping):
            raise PlantLoadError(f"knob {i}: constants must be a mapping, got {given!r}")
        unknown = sorted(set(given) - known)
        if unknown:
            raise PlantLoadError(f"knob {i}: unknown knob constant(s) {', '.join(unknown)}")
        try:
            p = dataclasses.replace(nominal, **{k: float(v) for k, v in given.items()})
        except (TypeError, ValueError):
            raise PlantLoadError(f"knob {i}: knob constants must be numbers") from None
        p.check(i)
        out.append(p)
    return tuple(out)


UNIT_SCATTER: dict[str, float] = {
    "pulley_radius_mm": 0.02,  # machined drum
    "slack_pos_mm": 0.15,  # tendon cut and crimped by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # wire-rope lot (EA: steel scatters less than polymer)
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "sheath_wrap_deg": 0.10,  # lumen path in the shaft
    "sheath_friction": 0.15,  # liner and how much lubricant assembly left
    "sheath_drag_N": 0.20,  # lumen ovality
    "film_damping_N_s_per_mm": 0.30,  # lubricant amount and viscosity: the least controlled
    "tendon_offset_mm": 0.05,  # lumen placement in the moulding
    "offset_ratio_neg": 0.03,  # the second lumen against the first (one mould)
    "bend_length_mm": 0.03,  # laser-cut spine length
    "cover_stiffness_Nm_per_rad": 0.15,  # silicone cover and braid
    "handle_friction_Nm": 0.20,  # knob O-ring squeeze
    "handle_presliding_deg": 0.20,
    "backbone_od_mm": 0.003,  # drawn NiTi tube: +-0.01 mm on 2 mm (the tube is one part:
    "backbone_id_mm": 0.003,  # the plant takes the mean of the two knobs' draws)
    "slot_stiffness_factor": 0.10,  # laser kerf width
    "austenite_modulus_GPa": 0.10,  # heat treatment of the lot
    "upper_plateau_MPa": 0.06,  # Af of the lot (+-3 K at 6.5 MPa/K) and processing
    "lower_plateau_MPa": 0.10,  # the lower plateau scatters more than the upper
    "transformation_strain": 0.10,
    "plateau_hardening": 0.20,  # cut pattern and texture
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
