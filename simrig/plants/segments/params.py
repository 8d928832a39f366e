"""The segments plant's constants: one knob's tendon pair and the whole-plant settings.

Every constant names its unit and where its magnitude comes from. "Paper" is the reference
paper in /work/shared/reference (ICE catheters, +-90 deg sweeps, loaded slope 1.32 +- 0.12, dead
zone and backlash of tens of knob degrees); "TEE" the real probe's data and README in
/work/shared/data/tee (currents up to about 150 mA under load, backlash about 10 % of the knob
range). The values were set on the plant alone, against those magnitudes, before tsmd ran on it.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from simrig.plant import PlantLoadError


@dataclass(frozen=True)
class SegmentsKnobParams:
    """One knob with its two antagonistic tendons ("+" drawn in by positive rotation)."""

    pulley_radius_mm: float = 6.0
    """Knob pulley radius. Handles of ICE/TEE catheters: knobs of 15-30 mm with a drum of
    4-8 mm; with the moment arm below it sets the geometric tip/knob ratio (2.4 here)."""
    slack_pos_mm: float = 2.50
    """Slack of the "+" tendon at straight: the dead zone (paper: D about 20-30 knob deg, i.e.
    2.1-3.1 mm on a 6 mm drum)."""
    slack_neg_mm: float = 2.60
    toe_mm: float = 0.30
    """Draw-in over which the free tendon's crimp straightens (the recruitment toe of a braided
    or crimped cable, 1-2 % strain of the free length)."""
    tendon_stiffness_N: float = 5000.0
    """Axial stiffness EA: a 0.18 mm steel wire (E 200 GPa) or a 0.3 mm braided aramid/UHMWPE
    cable. Sets the stretch, hence the backlash (paper: B tens of knob deg)."""
    free_length_m: float = 0.025
    """Tendon between pulley and sheath entry (handle geometry)."""
    sheath_length_m: float = 1.05
    """Sheath (insertion tube) length: ICE catheters are 90-110 cm."""
    sheath_friction: float = 0.18
    """Tendon-on-lumen friction coefficient: PTFE liner on steel 0.05-0.2, dry braid up to 0.3."""
    sheath_wrap_deg: float = 380.0
    """Total angle the tendon wraps in the straight sheath (lumen helix and contact waviness),
    the capstan exponent mu*wrap = 1.2 rad (tension ratio 3.3 end to end)."""
    sheath_drag_N: float = 0.12
    """Tension-independent friction over the whole sheath (lumen preload, seals)."""
    presliding_mm: float = 0.05
    """Elasto-plastic presliding displacement of a contact (Dupont et al. 2002: tens of
    micrometres for lubricated polymer-metal contacts)."""
    stick_fraction: float = 0.5
    """Share of the presliding displacement that is purely elastic (true stick) before the
    contact starts to slide (the model's z_ba / z_ss)."""
    tendon_offset_mm: float = 2.5
    """Moment arm of the tendons in the bending section (lumens near the wall of a 5-6 mm
    bending section)."""
    bend_stiffness_Nm_per_rad: float = 0.0060
    """Bending-section stiffness at straight (polymer cover over links; gives 3-6 N of distal
    tension at full bend, TEE currents of 100-150 mA through the drive)."""
    bend_stiffening_per_rad2: float = 0.35
    """Stiffness growth with bend, K(theta) = K0 (1 + c theta^2): the cover stretches and the
    links close up towards full bend."""
    bend_hysteresis_Nm: float = 0.0007
    """Amplitude of the bending section's own (Bouc-Wen) hysteresis: link-to-link rubbing."""
    bend_yield_deg: float = 4.0
    """Tip rotation over which the bending hysteresis builds up."""
    handle_friction_Nm: float = 0.010
    """Knob bearing and brake friction (a few mNm per bearing, TEE currents near 0 in the dead
    zone)."""
    handle_presliding_deg: float = 0.6
    """Knob rotation over which the handle friction builds up after a reversal."""


NOMINAL_KNOBS: tuple[SegmentsKnobParams, SegmentsKnobParams] = (
    SegmentsKnobParams(),
    SegmentsKnobParams(slack_pos_mm=2.65, slack_neg_mm=2.45, sheath_wrap_deg=360.0,
                       tendon_offset_mm=2.45),
)
"""Knob 1 (phi1) and knob 2 (phi2): the two pairs of one catheter differ a little."""


@dataclass(frozen=True)
class SegmentsPlantParams:
    """Whole-plant settings (not per knob)."""

    n_elements: int = 10
    """Sheath elements per tendon, each with its own friction state."""
    viscous_N_s_per_m: float = 2.0
    """Viscous drag of a tendon in its lubricated lumen, whole length (keeps the implicit step
    well posed while a tendon is slack; 0.02 N at the paper's fastest sweep)."""
    coupling: float = 1.0
    """Cross-coupling between the two planes (1 = nominal, 0 = independent knobs)."""
    coupling_lumen_angle_deg: float = 6.0
    """Lumens placed this far off their bending plane: the other plane's bend shifts the two
    tendons' paths oppositely by r_b sin(angle) theta_other."""
    coupling_compression_mm_per_N: float = 0.006
    """Axial compression of the coil sheath per newton of the other pair's tension (adds slack
    to both tendons of this pair)."""
    sheath_curvature_deg: float = 0.0
    """The sheath laid in a curve of this total angle: extra wrap on every element and a shorter
    tendon path (lumen clearance per radian)."""
    lumen_clearance_mm: float = 0.25
    """Radial play of a tendon in its lumen: a curved sheath lets it take the inner path."""


_POSITIVE = {"pulley_radius_mm", "toe_mm", "tendon_stiffness_N", "free_length_m",
             "sheath_length_m", "presliding_mm", "tendon_offset_mm", "bend_stiffness_Nm_per_rad",
             "bend_yield_deg", "handle_presliding_deg"}


def knob_params(knobs: Sequence[Mapping[str, Any]] | None
                ) -> tuple[SegmentsKnobParams, SegmentsKnobParams]:
    """The two knobs' constants: nominal values overridden by ``knobs`` (checked)."""
    if knobs is None:
        return NOMINAL_KNOBS
    if isinstance(knobs, (str, bytes)) or not isinstance(knobs, Sequence) or len(knobs) != 2:
        raise PlantLoadError(f"knobs must be a list of 2 mappings, got {knobs!r}")
    known = {f.name for f in dataclasses.fields(SegmentsKnobParams)}
    out = []
    for i, (base, given) in enumerate(zip(NOMINAL_KNOBS, knobs, strict=True)):
        if not isinstance(given, Mapping):
            raise PlantLoadError(f"knobs[{i}] must be a mapping, got {given!r}")
        unknown = sorted(set(given) - known)
        if unknown:
            raise PlantLoadError(f"knobs[{i}]: unknown parameter {unknown[0]!r}")
        values = dataclasses.asdict(base)
        for name, value in given.items():
            values[name] = _number(f"knobs[{i}].{name}", value, positive=name in _POSITIVE)
        if not 0.0 <= values["stick_fraction"] < 1.0:
            raise PlantLoadError(f"knobs[{i}].stick_fraction must be in [0, 1), "
                                 f"got {values['stick_fraction']}")
        out.append(SegmentsKnobParams(**values))
    return out[0], out[1]


def plant_params(settings: Mapping[str, Any]) -> SegmentsPlantParams:
    """Whole-plant settings from keywords (checked)."""
    known = {f.name for f in dataclasses.fields(SegmentsPlantParams)}
    unknown = sorted(set(settings) - known)
    if unknown:
        raise PlantLoadError(f"unknown plant parameter {unknown[0]!r}; known: knobs, "
                             f"{', '.join(sorted(known))}")
    values: dict[str, Any] = {}
    for name, value in settings.items():
        if name == "n_elements":
            if isinstance(value, bool) or not isinstance(value, int) or not 2 <= value <= 40:
                raise PlantLoadError(f"n_elements must be an integer in 2..40, got {value!r}")
            values[name] = value
        else:
            values[name] = _number(name, value, positive=False)
    return SegmentsPlantParams(**values)


def _number(name: str, value: Any, positive: bool) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise PlantLoadError(f"{name} must be a finite number, got {value!r}")
    if positive and value <= 0.0:
        raise PlantLoadError(f"{name} must be > 0, got {float(value)}")
    if not positive and value < 0.0:
        raise PlantLoadError(f"{name} must be >= 0, got {float(value)}")
    return float(value)


UNIT_SCATTER: dict[str, float] = {
    "pulley_radius_mm": 0.02,  # machined part
    "slack_pos_mm": 0.15,  # tendon cut and crimped by hand
    "slack_neg_mm": 0.15,
    "toe_mm": 0.20,  # crimp geometry
    "tendon_stiffness_N": 0.15,  # tendon lot (EA)
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "sheath_friction": 0.15,  # liner coating, lubricant
    "sheath_wrap_deg": 0.10,  # lumen helix pitch
    "sheath_drag_N": 0.20,  # lumen preload
    "presliding_mm": 0.20,  # contact micro-geometry
    "stick_fraction": 0.10,
    "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
    "bend_stiffness_Nm_per_rad": 0.15,  # polymer cover, links
    "bend_stiffening_per_rad2": 0.20,
    "bend_hysteresis_Nm": 0.20,  # link rubbing
    "bend_yield_deg": 0.20,
    "handle_friction_Nm": 0.20,  # knob bearing / brake setting
    "handle_presliding_deg": 0.20,
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
