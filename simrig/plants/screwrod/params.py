"""Constants of the screwrod plant, each with where its magnitude comes from.

Per knob (:class:`ScrewRodKnobParams`): the handle's helical collar (a steep lead screw with
two opposite-hand nuts, one per tendon), two UHMWPE fibre tendons, the sheath contact and the
Kirchhoff-rod bending section. Shared (:class:`WallParams`): the compliant wall the tip meets in
the anterior (knob 1, positive) direction.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields
from typing import Any

from simrig.plant import PlantLoadError


@dataclass(frozen=True)
class ScrewRodKnobParams:
    """One knob and its two antagonistic tendons (nominal unit)."""

    screw_lead_mm: float = 32.0
    """Slider travel per knob turn (5.09 mm per rad): a steep two-start collar thread; set
    (session 13, from 36.4) so that the loaded slope is near the paper's 1.32 tip/knob."""
    screw_radius_mm: float = 22.0
    """Mean thread radius of the 44 mm knob collar (TEE/ICE handles: 40-50 mm knobs)."""
    thread_friction: float = 0.28
    """Dry acetal-on-acetal thread (handbook 0.25-0.35): at this lead (13.0 deg) the collar is
    just self-locking (driving efficiency 0.42, back-driving -0.20), as steerable handles are
    built to hold their bend when let go."""
    handle_friction_Nm: float = 0.005
    """O-ring seal of the collar (TEE current near 0 in the dead zone: a few mA; set from
    0.008)."""
    handle_presliding_deg: float = 1.0
    """Knob travel over which the thread and seal friction turn round (elastic thread flanks)."""
    slack_pos_mm: float = 2.65
    slack_neg_mm: float = 2.65
    """Tendon slack at assembly; 2.65 mm is 30 knob deg on this collar (paper/TEE dead zones:
    tens of knob degrees; set from 2.1 between the engagement-rise and release-slope checks)."""
    toe_mm: float = 0.05
    """UHMWPE braid toe: elongation over which the braid's fibres straighten (a pre-stretched
    braid: 0.005 % of 1.25 m; set from 0.4 so that the torque rises on engagement)."""
    tendon_stiffness_N: float = 10000.0
    """EA of a 0.5 mm UHMWPE braid (E of the braid 50-100 GPa, ~0.15 mm^2; set from 6000 so
    that the tip releases at about its loaded slope, as on the TEE probe)."""
    creep_limit_mm: float = 0.4
    """Plastic elongation the tendon saturates at under load (UHMWPE primary creep, ~0.04 % of
    1 m over a procedure)."""
    creep_time_s: float = 240.0
    """Time to cover 1/e of the rest of that elongation at the reference tension."""
    creep_reference_N: float = 15.0
    """Tension at which the creep time holds (rate grows with tension squared, Norton n = 2)."""
    free_length_m: float = 0.25
    """Tendon from the collar to the sheath entry (handle)."""
    sheath_length_m: float = 1.0
    """Insertion tube (TEE/ICE: about 1 m)."""
    sheath_wrap_deg: float = 250.0
    """Total turning of the sheath path (curves in the body and the handle exit; set from 200);
    the bending section adds both planes' bends to it."""
    sheath_friction: float = 0.15
    """UHMWPE on a PTFE liner (0.1-0.2)."""
    sheath_drag_N: float = 0.15
    """Liner preload: friction of the tendon on its lumen at zero tension (set from 0.3: it
    holds the released tip off centre by about 3 deg)."""
    presliding_mm: float = 0.1
    """Tendon travel at the contact over which all of it slips (liner and braid compliance;
    set from 0.25)."""
    tendon_offset_mm: float = 2.5
    """Lumen offset from the bending section's axis (7 mm steerable section)."""
    bend_length_mm: float = 50.0
    """Length of the bending section (TEE/ICE: 40-60 mm)."""
    bend_stiffness_Nm_per_rad: float = 0.01
    """EI / length of the bending section (EI 5e-4 N m^2: soft Pebax and braid over 7 mm;
    set from 0.02 with the tendon's EA, same reason)."""
    bend_limit_deg: float = 90.0
    """Bend at which the section's link rims close (steerable TEE/ICE sections stop at
    90-120 deg); beyond it the closed links take the moment (tip ~94 deg at 180 knob deg)."""
    link_stiffness_Nm_per_rad: float = 1.0
    """Stiffness of the closed links (rim contact of moulded polymer links: ~100 x the open
    section)."""

    def slack_m(self, sign: int) -> float:
        return (self.slack_pos_mm if sign > 0 else self.slack_neg_mm) * 1e-3


@dataclass(frozen=True)
class WallParams:
    """The compliant wall (oesophagus or gastric wall) the tip meets when bent anteriorly."""

    wall_gap_mm: float = 28.0
    """Lateral distance from the section's axis to the wall: contact from about 74 deg of bend
    (oesophageal or gastric lumen ~20-30 mm; set from 24)."""
    wall_stiffness_N_per_mm: float = 0.1
    """Contact stiffness of the wall (soft-tissue indentation 0.05-0.5 N/mm)."""


NOMINAL_KNOBS = (ScrewRodKnobParams(), ScrewRodKnobParams())
NOMINAL_WALL = WallParams()

IWAN_SHARES = (0.2, 0.3, 0.5)
"""Shares of the contact's capacity held by each Jenkins element (Iwan distribution)."""
IWAN_SLIP_FRACTIONS = (0.2, 0.5, 1.0)
"""Each element slips after this fraction of ``presliding_mm``: the softest last."""

_MAY_BE_ZERO = {"handle_friction_Nm", "creep_limit_mm", "toe_mm", "slack_pos_mm",
                "slack_neg_mm", "free_length_m", "sheath_wrap_deg", "sheath_friction"}


def knob_params(values: dict[str, Any] | ScrewRodKnobParams) -> ScrewRodKnobParams:
    """One knob's constants checked: finite, positive (some may be zero); one clear line."""
    if isinstance(values, ScrewRodKnobParams):
        values = asdict(values)
    known = {f.name for f in fields(ScrewRodKnobParams)}
    unknown = set(values) - known
    if unknown:
        raise PlantLoadError(f"screwrod: unknown knob constant(s) {sorted(unknown)}")
    try:
        p = ScrewRodKnobParams(**{k: float(v) for k, v in values.items()})
    except (TypeError, ValueError):
        raise PlantLoadError(f"screwrod: knob constants must be numbers, got {values!r}") from None
    for f in fields(p):
        v = getattr(p, f.name)
        low_ok = v >= 0.0 if f.name in _MAY_BE_ZERO else v > 0.0
        if not (math.isfinite(v) and low_ok):
            raise PlantLoadError(f"screwrod: {f.name} must be finite and "
                                 f"{'>= 0' if f.name in _MAY_BE_ZERO else '> 0'}, got {v!r}")
    if p.screw_lead_mm / (2 * math.pi) >= p.screw_radius_mm:
        raise PlantLoadError("screwrod: screw_lead_mm / 2 pi must be below screw_radius_mm "
                             "(a lead angle under 45 deg)")
    return p


def wall_params(gap_mm: float, stiffness_N_per_mm: float) -> WallParams:
    w = WallParams(float(gap_mm), float(stiffness_N_per_mm))
    if not (math.isfinite(w.wall_gap_mm) and w.wall_gap_mm > 0.0):
        raise PlantLoadError(f"screwrod: wall_gap_mm must be finite and > 0, got {gap_mm!r}")
    if not (math.isfinite(w.wall_stiffness_N_per_mm) and w.wall_stiffness_N_per_mm >= 0.0):
        raise PlantLoadError("screwrod: wall_stiffness_N_per_mm must be finite and >= 0, "
                             f"got {stiffness_N_per_mm!r}")
    return w


def screw_factors(p: ScrewRodKnobParams) -> tuple[float, float]:
    """(mean, half-difference) of the collar's torque factors driving (1/eta_d) and
    back-driven (eta_b), from the lead angle and the thread's friction angle."""
    lead = math.atan(p.screw_lead_mm / (2.0 * math.pi * p.screw_radius_mm))
    rho = math.atan(p.thread_friction)
    drive = math.tan(lead + rho) / math.tan(lead)  # 1 / eta_d
    back = math.tan(lead - rho) / math.tan(lead)  # eta_b (< 0: self-locking)
    return 0.5 * (drive + back), 0.5 * (drive - back)


UNIT_SCATTER: dict[str, float] = {
    "screw_lead_mm": 0.01,  # moulded collar thread
    "screw_radius_mm": 0.01,
    "thread_friction": 0.15,  # dry polymer thread, grease left from assembly
    "handle_friction_Nm": 0.20,  # O-ring squeeze
    "handle_presliding_deg": 0.20,  # thread flank fit
    "slack_pos_mm": 0.15,  # tendon cut and knotted to its nut by hand
    "slack_neg_mm": 0.15,
    "toe_mm": 0.20,  # braid lay
    "tendon_stiffness_N": 0.15,  # braid lot (EA)
    "creep_limit_mm": 0.30,  # UHMWPE creep: lot and braid heat-setting scatter widely
    "creep_time_s": 0.30,
    "free_length_m": 0.20,  # handle assembly
    "sheath_length_m": 0.02,  # cut to length
    "sheath_wrap_deg": 0.10,  # lumen path in the shaft
    "sheath_friction": 0.15,  # liner coating, lubricant
    "sheath_drag_N": 0.20,  # lumen preload
    "presliding_mm": 0.20,  # liner and braid compliance
    "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
    "bend_length_mm": 0.03,  # moulded links
    "bend_stiffness_Nm_per_rad": 0.15,  # tip cover and braid
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
