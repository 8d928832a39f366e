"""Constants of the stick-slip plant, each with the source of its magnitude.

One knob drives a drum through a short cable drive; the drum pulls one polymer tendon and pays
out its antagonist; each tendon runs through the sheath over ``NODES_PER_TENDON`` contact nodes
with Karnopp stick-slip friction (normal force from local tension x local wrap) into a
pseudo-rigid-body tip of ``TIP_LINKS`` stiffening joints carrying the distal section's weight.
Magnitudes: a TEE-probe-sized catheter (1 m shaft, 12 mm tip, 50 mm bending section), the paper's
dead zone, backlash and slope (D, B tens of knob degrees, omega 1.32 +- 0.12), a drive current
of the TEE data's order (0.15 A there, ~0.25 A at full bend here).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from simrig.plant import PlantLoadError

NODES_PER_TENDON = 8
"""Sheath contact nodes per tendon (one per 12.5 cm of a 1 m shaft: each ~34 deg of wrap)."""
TIP_LINKS = 4
"""Pseudo-rigid-body links of the bending section (a 3-6 link chain fits a tendon-bent section
within a few per cent of its tip angle, Howell's PRB literature)."""
GRAVITY_M_S2 = 9.81
REGULARISATION = 1e-5
"""Numerical: a slack tendon segment keeps this share of its axial stiffness (no physics: it keeps
the Newton matrix regular when both tendons of a knob are slack; 0.02 deg at the tip)."""


class StickSlipParamError(PlantLoadError):
    """A constant of the stick-slip plant is out of its physical range."""


@dataclass(frozen=True)
class StickSlipKnobParams:
    """One knob: its drum and cable drive, its two tendons, its bending plane."""

    pulley_radius_mm: float = 8.0
    """Drum radius; with the 4 mm tendon offset a rigid draw would give a tip/knob slope of 2;
    tendon stretch brings the loaded slope down to the paper's ~1.3."""
    tendon_offset_mm: float = 4.0
    """Tendon lumen distance from the bending axis of a 12 mm TEE tip."""
    slack_pos_mm: float = 3.9
    """Slack of the pulling (+) tendon at the drum crimp: 3.9 mm is 28 knob deg on the 8 mm drum
    (paper/TEE: D ~ 20-25 deg)."""
    slack_neg_mm: float = 3.9
    toe_mm: float = 0.3
    """Braid straightening before the linear stretch (toe region of a polymer braid, ~0.2 % strain
    of the free segment)."""
    tendon_stiffness_N: float = 8000.0
    """Long-term axial stiffness EA of a 0.4-0.5 mm UHMWPE braid (fibre modulus ~100 GPa, braid
    ~40-55 % of it over ~0.15 mm^2). A softer tendon releases steeper than it loads, which the
    TEE probe does not (release/load 0.67-1.02)."""
    creep_fast_share: float = 0.25
    """Prony branch 1 stiffness / EA: braided UHMWPE relaxes 30-50 % of its stress within ~100 s
    (stress-relaxation tests of Dyneema/Spectra ropes and sutures)."""
    creep_fast_time_s: float = 0.5
    creep_slow_share: float = 0.30
    creep_slow_time_s: float = 12.0
    free_length_pos_m: float = 0.10
    """Tendon between drum and shaft inlet in the handle (+ tendon)."""
    free_length_neg_m: float = 0.13
    """The antagonist is routed round the drum's far side: longer, more compliant."""
    sheath_length_m: float = 1.0
    """Shaft of a TEE probe (~1 m)."""
    sheath_wrap_deg: float = 420.0
    """Total contact angle of a tendon in a straight shaft: helical lumens and the shaft's own
    meander (a turn and a bit of pitch; 360-450 deg gives the paper's backlash)."""
    sheath_friction: float = 0.20
    """Kinetic Coulomb coefficient, UHMWPE on a PTFE/Pebax liner (0.1-0.25)."""
    stiction_ratio: float = 1.15
    """Static / kinetic coefficient (1.1-1.4 for polymer pairs, low end for a lubricated PTFE
    liner); 1 removes stick-slip."""
    sheath_drag_N: float = 0.08
    """Tension-free drag of one tendon over the whole shaft (liner preload), shared by its nodes:
    a lubricious liner; the tip's own return must overcome it, so it sets how far from straight
    the tip stays in the dead zone (0.08 N: ~3 deg)."""
    bend_stiffness_Nm_per_rad: float = 0.012
    """Bending section stiffness (polymer cover over links, EI ~ 6e-4 N m^2 over 50 mm); with EA
    it sets the loaded slope (1.3-1.45) and the tension (~30 N at the drum at full bend: ~0.25 A
    at the drive through the 50:1 gear)."""
    bend_stiffening_per_rad2: float = 0.2
    """Joint stiffening: k(phi) = k0 (1 + c phi^2), phi the joint angle (cover strain-hardening)."""
    tip_mass_g: float = 4.0
    """Bending section with its transducer head (a TEE head and its links: grams to tens)."""
    tip_length_mm: float = 50.0
    """Bending section length, split into TIP_LINKS equal links."""
    drive_stiffness_Nm_per_rad: float = 4.0
    """Cable drive between the motor's shaft and the knob drum (steel cable loop, EA ~2 kN, two
    strands on a 10 mm capstan over 50 mm: ~8 N m/rad; half of it with the knob adapter's
    coupling)."""
    handle_friction_Nm: float = 0.012
    """Kinetic friction of the knob's friction brake (the knob lock, left slightly engaged)."""
    brake_stiction_ratio: float = 1.3
    """Static / kinetic ratio of the brake pad (felt/steel 1.2-1.5)."""

    def check(self) -> None:
        """Refuse non-physical constants with one line naming the first."""
        for f in fields(self):
            v = getattr(self, f.name)
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
                raise StickSlipParamError(f"{f.name} must be a finite number, got {v!r}")
        positive = ("pulley_radius_mm", "tendon_offset_mm", "toe_mm", "tendon_stiffness_N",
                    "creep_fast_time_s", "creep_slow_time_s", "free_length_pos_m",
                    "free_length_neg_m", "sheath_length_m", "bend_stiffness_Nm_per_rad",
                    "tip_length_mm", "drive_stiffness_Nm_per_rad")
        for name in positive:
            if getattr(self, name) <= 0.0:
                raise StickSlipParamError(f"{name} must be > 0, got {getattr(self, name)!r}")
        for name in ("slack_pos_mm", "slack_neg_mm", "creep_fast_share", "creep_slow_share",
                     "sheath_wrap_deg", "sheath_friction", "sheath_drag_N",
                     "bend_stiffening_per_rad2", "tip_mass_g", "handle_friction_Nm"):
            if getattr(self, name) < 0.0:
                raise StickSlipParamError(f"{name} must be >= 0, got {getattr(self, name)!r}")
        for name in ("stiction_ratio", "brake_stiction_ratio"):
            if getattr(self, name) < 1.0:
                raise StickSlipParamError(f"{name} must be >= 1, got {getattr(self, name)!r}")


NOMINAL_KNOBS = (StickSlipKnobParams(), StickSlipKnobParams())
"""The nominal unit: both knobs alike (the family scatters them independently)."""


UNIT_SCATTER: dict[str, float] = {
    "pulley_radius_mm": 0.02,  # machined drum
    "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
    "slack_pos_mm": 0.15,  # tendon cut and crimped by hand
    "slack_neg_mm": 0.15,
    "toe_mm": 0.20,  # crimp and braid lay
    "tendon_stiffness_N": 0.15,  # braid lot (EA)
    "creep_fast_share": 0.20,  # polymer lot and braid tension: relaxation scatters widely
    "creep_fast_time_s": 0.30,
    "creep_slow_share": 0.20,
    "creep_slow_time_s": 0.30,
    "free_length_pos_m": 0.20,  # handle assembly
    "free_length_neg_m": 0.20,
    "sheath_length_m": 0.02,  # cut to length
    "sheath_wrap_deg": 0.10,  # lumen helix pitch
    "sheath_friction": 0.15,  # liner coating, lubricant
    "stiction_ratio": 0.05,  # one material pair
    "sheath_drag_N": 0.20,  # liner preload
    "bend_stiffness_Nm_per_rad": 0.15,  # tip cover and links
    "bend_stiffening_per_rad2": 0.20,  # cover strain-hardening, polymer batch
    "tip_mass_g": 0.10,  # transducer head and links
    "tip_length_mm": 0.03,  # moulded links
    "drive_stiffness_Nm_per_rad": 0.20,  # cable tension set at assembly, coupling fit
    "handle_friction_Nm": 0.25,  # knob brake as left by the last user: the least controlled
    "brake_stiction_ratio": 0.05,  # one pad material
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
