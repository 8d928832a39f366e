"""Constants of the coil-pipe plant, each with where its magnitude comes from.

Lengths in mm or m, forces in N, torques in N m, angles in degrees, as the names say. One
:class:`CoilPipeKnobParams` per knob (its antagonistic tendon pair, pulley, handle gear and the
tip plane it bends), one :class:`CoilPipePlantParams` for what both knobs share (the shaft).
Sources of the magnitudes: the compensation paper in /work/shared/reference (omega 1.32 +- 0.12,
dead zone and backlash of tens of knob degrees at +-90 deg sweeps), the real TEE probe data
(/work/shared/data/tee: about 10 % of the knob range of play, +-150 mA of motor current under
load, which with the rig's 0.0302 N m/A motor, 50:1 gear at 75 % is about 0.17 N m at the knob),
and handbook values for the materials named per constant.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from simrig.plant import PlantLoadError


class CoilPipeParamError(PlantLoadError):
    """A constant of the coil-pipe plant is outside its physical range."""


@dataclass(frozen=True)
class CoilPipeKnobParams:
    """One knob: pulley, handle gear, two tendons in a coil-pipe lumen, one tip plane."""

    pulley_radius_mm: float = 8.0
    """Knob drum radius: TEE/ICE handles have drums of 12-20 mm diameter."""
    tendon_offset_mm: float = 4.5
    """Tendon lumen distance from the tip's neutral axis: a 10-12 mm TEE tip, lumens at the wall.
    Rigid tendons would give tip/knob = 8/4.5 = 1.78; compliance brings it to the paper's ~1.3."""
    slack_pos_mm: float = 2.8
    """Slack of the tendon pulled by positive knob angles: 2.8 mm = 20 knob deg, the paper's and
    the TEE probe's dead zone of about 20 deg."""
    slack_neg_mm: float = 2.8
    toe_mm: float = 0.4
    """Strand settling of a 7x7 cable before it carries its full stiffness (crimp, lay)."""
    tendon_stiffness_N: float = 9000.0
    """EA of a 0.4 mm 7x7 stainless cable: ~0.09 mm^2 metal at ~100 GPa effective modulus."""
    free_length_m: float = 0.10
    """Tendon between the drum and the shaft entry inside the handle."""
    sheath_length_m: float = 1.0
    """Insertion tube of a TEE probe (about 1 m)."""
    sheath_friction: float = 0.12
    """Kinetic friction coefficient of a steel cable on a PTFE liner (0.05-0.2)."""
    sheath_wrap_deg: float = 290.0
    """Total angle the lumen turns through on a straight-laid shaft (helical lumens, lay of the
    coil): with mu 0.12 the tension ratio across the sheath is exp(0.61) = 1.84."""
    sheath_drag_N: float = 0.3
    """Load-independent drag of the lumen (cable pressed by the liner's preload)."""
    stribeck_ratio: float = 1.3
    """Static over kinetic friction of PTFE on steel (1.1-1.5)."""
    stribeck_speed_mm_s: float = 2.0
    """Speed over which friction falls from static to kinetic; lubricated polymer contacts
    1-10 mm/s (knob at 120 deg/s draws 15 mm/s)."""
    viscous_N_s_per_mm: float = 0.02
    """Viscous drag of the lubricated lumen over the whole sheath (0.3 N at 15 mm/s)."""
    presliding_mm: float = 0.05
    """LuGre bristle deflection at break-away: tens of micrometres on polymer liners."""
    bend_stiffness_Nm_per_rad: float = 0.03
    """Relaxed bending stiffness of the steerable tip (Pebax cover, links): 10 N of distal
    tension at 4.5 mm holds about 85 deg."""
    bend_creep_stiffness_Nm_per_rad: float = 0.006
    """Extra short-time stiffness that relaxes: Pebax loses 15-40 % of its stress in seconds."""
    bend_creep_time_s: float = 2.0
    """Relaxation time of the tip cover (polyether block amides: 0.5-10 s)."""
    handle_friction_Nm: float = 0.02
    """Knob bearing and detent friction at the drum."""
    handle_presliding_deg: float = 0.5
    gear_backlash_deg: float = 1.0
    """Total gap of the handle gear between the drive shaft and the knob (an adapter's spur pair:
    0.05-0.1 mm of tooth play on a 5-10 mm pitch radius), in knob degrees."""
    gear_stiffness_Nm_per_deg: float = 0.3
    """Torsional stiffness of the gear and adapter, 0.6 deg of wind-up at 0.2 N m."""


@dataclass(frozen=True)
class CoilPipePlantParams:
    """What both knobs share."""

    shaft_stiffness_N_per_mm: float = 80.0
    """Axial stiffness of the coil-pipe shaft under the sum of the four tendon tensions:
    a close-wound coil under a polymer jacket shortens ~0.4 mm at 30 N over 1 m."""
    sections: int = 4
    """Sheath sections per tendon, each a friction contact of its own."""
    coupling_mm_per_rad2: float = 0.25
    """Bending the other plane shortens the tendon path through the bending section (rim
    compression of a ~60 mm section with 4.5 mm offset gives tenths of a mm per rad^2)."""
    bend_section_wrap_ratio: float = 1.0
    """Wrap the tendon gains in the bending section per radian of its own tip bend."""
    sheath_curvature_deg: float = 0.0
    """Effect: the sheath laid in a curve of this total angle (adds wrap to the middle sections
    and shortens the tendon path by the lumen clearance)."""
    lumen_clearance_mm: float = 0.3
    """Lumen radius minus tendon radius: path shortening per radian of sheath curvature."""


_POSITIVE = {"pulley_radius_mm", "tendon_offset_mm", "tendon_stiffness_N", "free_length_m",
             "sheath_length_m", "stribeck_speed_mm_s", "presliding_mm",
             "bend_stiffness_Nm_per_rad", "bend_creep_time_s", "handle_presliding_deg",
             "gear_stiffness_Nm_per_deg", "toe_mm"}


def check_knob(p: CoilPipeKnobParams, index: int) -> None:
    """Refuse a knob's constants outside their physical range (one named line)."""
    where = f"coilpipe knobs[{index}]."
    for f in fields(p):
        value = getattr(p, f.name)
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(
                value):
            raise CoilPipeParamError(f"{where}{f.name} must be a finite number, got {value!r}")
        if f.name in _POSITIVE and not value > 0:
            raise CoilPipeParamError(f"{where}{f.name} must be > 0, got {value}")
        if value < 0:
            raise CoilPipeParamError(f"{where}{f.name} must be >= 0, got {value}")
    if p.stribeck_ratio < 1.0:
        raise CoilPipeParamError(f"{where}stribeck_ratio must be >= 1, got {p.stribeck_ratio}")


def check_plant(p: CoilPipePlantParams) -> None:
    """Refuse the shared constants outside their physical range (one named line)."""
    if isinstance(p.sections, bool) or not isinstance(p.sections, int) or not 1 <= p.sections <= 12:
        raise CoilPipeParamError(f"coilpipe parameter sections must be an integer in 1..12, got "
                                 f"{p.sections!r}")
    for name in ("shaft_stiffness_N_per_mm", "coupling_mm_per_rad2", "bend_section_wrap_ratio",
                 "sheath_curvature_deg", "lumen_clearance_mm"):
        value = getattr(p, name)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(
                value) or value < 0:
            raise CoilPipeParamError(f"coilpipe parameter {name} must be a finite number >= 0, "
                                     f"got {value!r}")
    if not p.shaft_stiffness_N_per_mm > 0:
        raise CoilPipeParamError("coilpipe parameter shaft_stiffness_N_per_mm must be > 0")


NOMINAL_KNOBS = (CoilPipeKnobParams(), CoilPipeKnobParams())


UNIT_SCATTER: dict[str, float] = {
    "pulley_radius_mm": 0.02,  # machined drum
    "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
    "slack_pos_mm": 0.15,  # tendon cut and crimped by hand
    "slack_neg_mm": 0.15,
    "toe_mm": 0.20,  # crimp and strand lay
    "tendon_stiffness_N": 0.15,  # cable lot (EA)
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "sheath_friction": 0.15,  # liner coating, lubricant
    "sheath_wrap_deg": 0.10,  # lumen helix pitch
    "sheath_drag_N": 0.25,  # liner preload on the cable
    "stribeck_ratio": 0.05,  # static/kinetic ratio of the liner (1.24-1.37 at 1.3)
    "stribeck_speed_mm_s": 0.30,  # lubricant film: the least known of the friction constants
    "viscous_N_s_per_mm": 0.30,  # lubricant amount and viscosity
    "presliding_mm": 0.20,  # contact micro-geometry
    "bend_stiffness_Nm_per_rad": 0.15,  # tip cover and links
    "bend_creep_stiffness_Nm_per_rad": 0.25,  # polymer batch, moulding
    "bend_creep_time_s": 0.30,
    "handle_friction_Nm": 0.20,  # knob bearing / detent setting
    "handle_presliding_deg": 0.20,
    "gear_backlash_deg": 0.30,  # adapter tooth play (tolerance stack of two parts)
    "gear_stiffness_Nm_per_deg": 0.20,  # adapter material and fit
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
