"""Constants of the archwave plant: one set per knob, and the patient's path of the shaft.

Per knob (:class:`ArchWaveKnob`): the drive's motor and strain-wave gearhead, the handle's
spring-loaded tendon tensioners, the tendons in their coil sheaths, the bending section. The
path (:class:`ShaftPath`) is the anatomy the shaft lies in, not the unit: two bends in
different planes (aortic arch or oesophagus, then the gastric or atrial turn).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from simrig.plant import PlantLoadError


@dataclass(frozen=True)
class ArchWaveKnob:
    """One knob's drive, handle, tendon pair and bending plane (SI-ish units in the names)."""

    # motor (what the drive's data sheet does not say)
    torque_constant_ratio: float = 1.0
    """True torque constant over the data sheet's (winding and magnet lot, +-8 %)."""
    kt_temp_coeff_per_K: float = 0.0011
    """Fall of the torque constant per kelvin of magnet warming (NdFeB: 0.11 %/K)."""
    standby_power_W: float = 1.1
    """Heat the drive and motor dissipate in the sealed handle at rest."""
    thermal_resistance_K_per_W: float = 24.0
    thermal_time_s: float = 240.0
    """Winding and housing: one thermal node."""
    winding_resistance_ohm: float = 5.2
    cogging_mNm: float = 0.06
    """Peak cogging torque at the motor shaft."""
    cogging_per_rev: float = 18.0
    """Cogging periods per motor revolution (LCM of 9 slots, 6 poles)."""
    gear_ratio: float = 50.0
    """Strain-wave gearhead ratio (the drive's gear_ratio)."""
    # strain-wave gearhead (polymer flexspline), at its output
    flex_stiffness_Nm_per_rad: float = 5.0
    flex_stiffening_Nm_per_rad3: float = 2000.0
    flex_elastic_share: float = 0.6
    """Share of the small-twist stiffness that is elastic; the rest is Bouc-Wen hysteresis."""
    flex_hysteresis_deg: float = 2.0
    """Twist at which the hysteretic part saturates (tooth-flank micro-slip)."""
    kinematic_error_deg: float = 0.15
    """Peak transmission error, twice per output revolution."""
    kinematic_phase_deg: float = 30.0
    wave_drag_Nm: float = 0.010
    """Wave-generator bearing and tooth rubbing (Coulomb, at the output)."""
    wave_viscous_Nm_s_per_rad: float = 0.004
    # handle: drum and spring-loaded tensioners
    pulley_radius_mm: float = 7.5
    handle_friction_Nm: float = 0.012
    """Knob shaft seal on the catheter's handle."""
    tensioner_preload_N: float = 0.08
    tensioner_rate_N_per_mm: float = 0.01
    """Soft spring of the idler, as seen by the tendon."""
    slack_pos_mm: float = 2.4
    """Idler travel the drum takes up before the idler bottoms out (pos tendon)."""
    slack_neg_mm: float = 2.4
    tensioner_reserve_mm: float = 5.0
    """Idler travel the other way before it rests on its outer stop (the tendon goes slack)."""
    # tendons in coil sheaths
    tendon_stiffness_N: float = 20000.0
    """EA of the steel wire rope."""
    sheath_length_m: float = 1.1
    free_length_m: float = 0.1
    coil_compliance_mm_per_N: float = 0.09
    """Coil sheath shortening under the tendon's load (gaps closing between turns)."""
    sheath_friction: float = 0.16
    sheath_wrap_deg: float = 90.0
    """The shaft's lay outside the two path bends (its own gentle turns)."""
    sheath_drag_N: float = 0.02
    coil_clearance_mm: float = 0.10
    """Radial play of the tendon in its coil: a bend shortens the tendon's path by it."""
    lumen_offset_mm: float = 0.25
    """Offset of the coil bundle from the shaft's neutral axis."""
    # bending section
    tendon_offset_mm: float = 4.5
    bend_stiffness_Nm_per_rad: float = 0.015
    bend_stiffening_per_rad2: float = 0.10
    """Cover strain-hardening with the total bend (both planes)."""
    section_wrap_share: float = 0.5
    """Share of the section's total bend that adds to every tendon's wrap."""


@dataclass(frozen=True)
class ShaftPath:
    """The patient's path: two bends in different planes (plane angle from phi1's pos lumen)."""

    arch_deg: float = 150.0
    arch_plane_deg: float = 20.0
    turn_deg: float = 55.0
    turn_plane_deg: float = 115.0


NOMINAL_KNOBS = (ArchWaveKnob(), ArchWaveKnob(kinematic_phase_deg=75.0))
"""Nominal unit: both knobs alike but the gearheads' phase."""

_POSITIVE = ("tendon_stiffness_N", "sheath_length_m", "pulley_radius_mm", "tendon_offset_mm",
             "bend_stiffness_Nm_per_rad", "flex_stiffness_Nm_per_rad", "flex_hysteresis_deg",
             "thermal_time_s", "gear_ratio", "torque_constant_ratio", "cogging_per_rev",
             "tensioner_rate_N_per_mm")


def _check_knob(k: ArchWaveKnob) -> None:
    for f in dataclasses.fields(k):
        v = getattr(k, f.name)
        if not math.isfinite(v):
            raise PlantLoadError(f"archwave {f.name} must be finite, got {v!r}")
        if f.name in _POSITIVE and not v > 0:
            raise PlantLoadError(f"archwave {f.name} must be > 0, got {v!r}")
        if f.name not in _POSITIVE and f.name != "kinematic_phase_deg" and v < 0:
            raise PlantLoadError(f"archwave {f.name} must be >= 0, got {v!r}")
    if not 0.0 < k.flex_elastic_share <= 1.0:
        raise PlantLoadError("archwave flex_elastic_share must be in (0, 1]")
    if k.tensioner_preload_N < k.tensioner_rate_N_per_mm * k.tensioner_reserve_mm:
        raise PlantLoadError("archwave tensioner_reserve_mm must not exceed the preload's "
                             "travel (tensioner_preload_N / tensioner_rate_N_per_mm)")


def knobs_from(knobs: Sequence[Mapping[str, Any]] | None) -> tuple[ArchWaveKnob, ArchWaveKnob]:
    """Two knobs' constants from dicts (missing names take the nominal value), checked."""
    if knobs is None:
        return NOMINAL_KNOBS
    if len(knobs) != 2:
        raise PlantLoadError(f"archwave takes 2 knobs, got {len(knobs)}")
    names = {f.name for f in dataclasses.fields(ArchWaveKnob)}
    out = []
    for nominal, given in zip(NOMINAL_KNOBS, knobs, strict=True):
        unknown = sorted(set(given) - names)
        if unknown:
            raise PlantLoadError(f"unknown archwave knob constants: {', '.join(unknown)}")
        try:
            k = dataclasses.replace(nominal, **{n: float(v) for n, v in given.items()})
        except (TypeError, ValueError):
            raise PlantLoadError(f"archwave knob constants must be numbers: {given!r}") from None
        _check_knob(k)
        out.append(k)
    return out[0], out[1]


def path_from(given: Mapping[str, Any]) -> ShaftPath:
    """The shaft's path from keywords (missing names take the default path), checked."""
    names = {f.name for f in dataclasses.fields(ShaftPath)}
    unknown = sorted(set(given) - names)
    if unknown:
        raise PlantLoadError(f"unknown archwave path constants: {', '.join(unknown)}")
    try:
        path = ShaftPath(**{n: float(v) for n, v in given.items()})
    except (TypeError, ValueError):
        raise PlantLoadError(f"archwave path constants must be numbers: {dict(given)!r}") from None
    for n in ("arch_deg", "turn_deg"):
        v = getattr(path, n)
        if not (math.isfinite(v) and 0.0 <= v <= 360.0):
            raise PlantLoadError(f"archwave {n} must be in [0, 360], got {v!r}")
    for n in ("arch_plane_deg", "turn_plane_deg"):
        if not math.isfinite(getattr(path, n)):
            raise PlantLoadError(f"archwave {n} must be finite")
    return path


UNIT_SCATTER: dict[str, float] = {
    "torque_constant_ratio": 0.08,  # motor lot: magnet and winding (+-8 % on the sheet)
    "standby_power_W": 0.20,  # drive electronics and hold current
    "thermal_resistance_K_per_W": 0.15,  # how the motor sits in the sealed handle
    "cogging_mNm": 0.30,  # magnet segment placement
    "flex_stiffness_Nm_per_rad": 0.20,  # moulded polymer flexspline: lot and wall thickness
    "flex_stiffening_Nm_per_rad3": 0.25,
    "flex_hysteresis_deg": 0.30,  # tooth-flank fit
    "kinematic_error_deg": 0.40,  # wave generator ellipse and tooth profile tolerance
    "kinematic_phase_deg": 1.0,  # where the error peaks: assembly (any phase)
    "wave_drag_Nm": 0.25,  # bearing preload, grease
    "pulley_radius_mm": 0.02,  # moulded drum
    "handle_friction_Nm": 0.20,  # knob shaft seal squeeze
    "tensioner_preload_N": 0.20,  # spring lot and idler position
    "tensioner_rate_N_per_mm": 0.15,  # spring lot
    "slack_pos_mm": 0.15,  # tendon wound and crimped by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # wire-rope lot (steel)
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "coil_compliance_mm_per_N": 0.25,  # coil pitch and how it was pre-compressed
    "sheath_friction": 0.15,  # coil and rope surface, lubricant
    "sheath_wrap_deg": 0.10,  # the shaft's lay
    "sheath_drag_N": 0.20,  # coil ovality
    "coil_clearance_mm": 0.20,  # coil inner diameter vs rope
    "lumen_offset_mm": 0.30,  # where the coil bundle sits in the shaft
    "tendon_offset_mm": 0.05,  # lumen placement in the section
    "bend_stiffness_Nm_per_rad": 0.15,  # cover durometer and spine cut
    "bend_stiffening_per_rad2": 0.20,
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
