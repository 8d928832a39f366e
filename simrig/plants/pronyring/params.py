"""Constants of the pronyring catheter (a TEE-sized probe) and their checks.

Sources of the nominal values (order of magnitude, not one data sheet):

* section: a Pebax 55D/35D multi-lumen extrusion over a coil, 60 mm long. Thermoplastic
  elastomers relax with a broad spectrum of times; a three-term Prony series (seconds, tens of
  seconds, minutes) is the usual fit of creep tests on Pebax and polyurethane tubing. The
  instantaneous (glassy) stiffness is about 1.6x the long-term (rubbery) one here.
* pull ring: a stainless ring bonded into the section's distal Pebax; the bond line and the
  polymer under it give the ring a tilt and an axial compliance; its four rope anchors are
  clocked off the bending planes by the assembly's tolerance (a few degrees).
* ropes: 1x19 stainless, 0.35 mm, 1.25 m from drum to ring (EA about 11 kN);
* liner: PTFE. Polymer-on-steel friction falls with contact load (Bowden and Tabor: elastic
  junctions, mu ~ load^(-1/3)); mu about 0.08-0.12 at tens of newtons on a lubricated liner.
* path: mouth to mid-oesophagus, the probe takes the oropharyngeal bend (~90 deg) and the
  oesophagus' curve behind the heart; breathing (0.25 Hz) bends the lower oesophagus by a few
  degrees, in the anterior-posterior plane.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

from simrig.plant import PlantLoadError


@dataclass(frozen=True)
class KnobConstants:
    """Per knob (one bending plane, one pair of ropes) constants."""

    drum_radius_mm: float = 9.4
    handle_friction_Nm: float = 0.05
    """Knob shaft seal and bearing (Coulomb, smoothed over a small speed)."""
    slack_pos_mm: float = 4.5
    """Rope pulled by a positive knob turn: drum travel before it tightens."""
    slack_neg_mm: float = 4.7
    tendon_stiffness_N: float = 11000.0
    """Axial rigidity EA of one rope (N)."""
    sheath_length_m: float = 1.25
    tendon_offset_mm: float = 4.0
    """Lumen's distance from the section's neutral axis (moment arm at the pull ring)."""
    shaft_offset_mm: float = 0.6
    """Lumen's distance from the shaft's axis (path change when the shaft bends)."""
    contact_fraction: float = 0.20
    """Where along the rope (from the drum) the path's friction acts: the oropharyngeal bend."""
    sheath_friction: float = 0.33
    """PTFE liner friction coefficient at the reference load."""
    friction_load_exponent: float = 0.15
    """mu ~ (load / reference)^(-exponent): polymer junctions (Bowden-Tabor)."""
    friction_reference_N: float = 10.0
    sheath_wrap_deg: float = 200.0
    """Total wrap of the path (handle routing, oropharynx, oesophagus)."""
    sheath_drag_N: float = 0.25
    """Load-independent drag of the rope in its lumen (fit)."""
    bend_stiffness_Nmm_per_rad: float = 60.0
    """Long-term (rubbery) bending stiffness of the section."""
    prony_fast_Nmm_per_rad: float = 12.0
    prony_fast_s: float = 3.0
    prony_mid_Nmm_per_rad: float = 10.0
    prony_mid_s: float = 40.0
    prony_slow_Nmm_per_rad: float = 6.0
    prony_slow_s: float = 400.0
    ring_tilt_Nmm_per_rad: float = 900.0
    """Tilt stiffness of the pull ring on its bond."""
    ring_axial_N_per_mm: float = 70.0
    """Axial stiffness of the ring's seat (all four ropes push the ring proximally)."""
    ring_friction_mm: float = 0.6
    """Friction moment of the ring's seat per newton of axial load (coefficient x seat radius)."""
    ring_clocking_deg: float = 6.0
    """Anchor clocking off the bending plane: this plane's moment tilts the ring toward the
other."""
    breathing_wrap_deg: float = 4.0
    """Breathing's bend of the lower oesophagus (amplitude); anterior-posterior plane only."""


NOMINAL_KNOBS = (KnobConstants(), KnobConstants(slack_pos_mm=4.7,
                                                slack_neg_mm=4.5, sheath_wrap_deg=190.0,
                                                bend_stiffness_Nmm_per_rad=52.0,
                                                breathing_wrap_deg=0.0))

BREATHING_HZ = 0.25
KNOB_SPEED_DEG_S = 2.0
"""Speed over which the knob's seal friction builds up (smoothing keeps the step deterministic)."""

_POSITIVE = ("drum_radius_mm", "tendon_stiffness_N", "sheath_length_m", "tendon_offset_mm",
             "friction_reference_N", "bend_stiffness_Nmm_per_rad", "prony_fast_s", "prony_mid_s",
             "prony_slow_s", "ring_tilt_Nmm_per_rad", "ring_axial_N_per_mm")


def knob_constants(values: dict[str, Any]) -> KnobConstants:
    """One knob's constants from a dict (unknown names and bad values refused, one line)."""
    known = {f.name for f in fields(KnobConstants)}
    unknown = sorted(set(values) - known)
    if unknown:
        raise PlantLoadError(f"unknown pronyring knob constants: {', '.join(unknown)}")
    k = KnobConstants(**{n: float(v) for n, v in values.items()})
    for f in fields(KnobConstants):
        v = getattr(k, f.name)
        if not math.isfinite(v):
            raise PlantLoadError(f"pronyring {f.name} must be finite, got {v}")
        if f.name == "contact_fraction" and not 0.0 < v < 1.0:
            raise PlantLoadError(f"pronyring contact_fraction must be in (0, 1), got {v}")
        if f.name in _POSITIVE and not v > 0.0:
            raise PlantLoadError(f"pronyring {f.name} must be > 0, got {v}")
        if f.name not in _POSITIVE and v < 0.0 and f.name != "ring_clocking_deg":
            raise PlantLoadError(f"pronyring {f.name} must be >= 0, got {v}")
    return k


UNIT_SCATTER: dict[str, float] = {
    "drum_radius_mm": 0.02,  # moulded drum
    "handle_friction_Nm": 0.20,  # knob seal
    "slack_pos_mm": 0.15,  # rope cut and crimped by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # rope lot (EA)
    "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
    "shaft_offset_mm": 0.10,
    "sheath_friction": 0.15,  # liner lot, lubricant
    "friction_load_exponent": 0.20,
    "sheath_wrap_deg": 0.10,  # routing in the handle, the patient's path
    "sheath_drag_N": 0.20,  # lumen fit
    "bend_stiffness_Nmm_per_rad": 0.12,  # Pebax lot, wall thickness
    "prony_fast_Nmm_per_rad": 0.20,  # relaxation spectrum of the lot
    "prony_fast_s": 0.25,
    "prony_mid_Nmm_per_rad": 0.20,
    "prony_slow_Nmm_per_rad": 0.25,
    "ring_tilt_Nmm_per_rad": 0.25,  # bond line thickness
    "ring_axial_N_per_mm": 0.20,
    "ring_clocking_deg": 0.50,  # anchor clocking: assembly tolerance
    "breathing_wrap_deg": 0.40,  # the patient
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
