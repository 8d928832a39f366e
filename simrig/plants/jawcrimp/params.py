"""Constants of the jawcrimp plant, their sources, and the checks a factory runs on them.

One :class:`JawCrimpKnob` per knob (the family scatters these per unit). The shaft is one part
for both knobs: its constants are read as the mean of the two knobs' values, so a unit's
scatter still moves them.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from simrig.plant import PlantLoadError


@dataclass(frozen=True)
class JawCrimpKnob:
    """One knob's drive train, tendon pair and bending plane (phi1 AP, phi2 RL).

    Sources: jaw couplings of 14-20 mm hub diameter (catalogue torsional stiffness of a
    92 Shore A spider about 2-10 N m/rad at rated torque, soft near zero load, 1-2 deg of
    play once the spider has set); steel wire rope 7x7, 0.45 mm (EA about 2e4 N); PTFE-lined
    lumen on steel rope, mu about 0.1-0.35; plain-bushed idler pulleys (bushing/pulley radius
    about 0.25, bushing mu about 0.15, 90 deg wrap: 5 % per idler); a TEE shaft of 1 m, 12 mm
    diameter, lumens about 4 mm off the axis; crimp creep of a swaged pull ring (slip rate of a
    power law in the load, hardening with the slip, after the crimp literature's log-time
    creep); the heart's contact on the oesophagus wall: a pulsatile moment of a fraction of a
    N mm at about 70 beats per minute.
    """

    pulley_radius_mm: float = 6.5
    """Drum radius on the knob shaft."""
    jaw_play_deg: float = 0.8
    """Half of the spider's play (the drum turns this far either way with no elastomer squeeze)."""
    jaw_play_stiffness_Nm_per_rad: float = 0.02
    """The set spider's residual stiffness inside the play."""
    jaw_twist_deg: float = 1.0
    """Scale of the squeeze law: twist = jaw_twist * asinh(torque / jaw_torque) past the play."""
    jaw_torque_Nm: float = 0.03
    slack_pos_mm: float = 2.45
    slack_neg_mm: float = 2.45
    tendon_stiffness_N: float = 20000.0
    """Axial stiffness EA of the steel rope."""
    free_length_m: float = 0.12
    """Rope from the drum over the idlers to the shaft entry."""
    sheath_length_m: float = 1.0
    node_share: float = 0.4
    """Where the lumped friction node sits along the shaft (share of its length proximal of it)."""
    sheath_friction: float = 0.34
    sheath_wrap_deg: float = 150.0
    """Total curve of the tendon's lumen along the shaft (in the oesophagus)."""
    sheath_drag_N: float = 0.5
    """Load-free drag at the node: lumen seal and the idlers' bearing preload."""
    idler_friction: float = 0.06
    """Tension lost per idler pulley (bushing friction x bushing/pulley radius x wrap force)."""
    idler_count: int = 2
    idler_inertia_kgm2: float = 2.0e-7
    """Drum plus idlers reflected to the knob shaft."""
    tendon_offset_mm: float = 4.0
    bend_stiffness_Nmm_per_rad: float = 20.0
    bend_stiffening_per_rad2: float = 0.02
    """Stiffening with the total bend (both planes): the cover's strain."""
    shaft_gap_mm: float = 0.45
    """Coil-gap closure of the shaft under axial load (closes first, then the solid stiffness)."""
    shaft_gap_load_N: float = 3.0
    shaft_stiffness_N_per_mm: float = 150.0
    crimp_creep_mm_per_s: float = 1.0e-3
    crimp_creep_load_N: float = 10.0
    crimp_creep_exponent: float = 3.0
    crimp_hardening_mm: float = 0.05
    handle_friction_Nm: float = 0.008
    """Knob shaft seal (Coulomb, smoothed over handle_speed_deg_s)."""
    handle_speed_deg_s: float = 2.0
    tissue_moment_Nmm: float = 12.0
    """The oesophagus wall the tip must push aside: a stiff start saturating at this moment."""
    tissue_angle_deg: float = 8.0
    heart_moment_Nmm: float = 0.4
    heart_phase_deg: float = 0.0
    heart_rate_hz: float = 1.15


NOMINAL_KNOBS: tuple[JawCrimpKnob, JawCrimpKnob] = (
    JawCrimpKnob(),
    JawCrimpKnob(tendon_offset_mm=3.8, bend_stiffness_Nmm_per_rad=18.0, sheath_wrap_deg=140.0,
                 slack_pos_mm=2.35, slack_neg_mm=2.55, heart_moment_Nmm=0.25,
                 heart_phase_deg=70.0),
)

_POSITIVE = ("pulley_radius_mm", "jaw_twist_deg", "jaw_torque_Nm", "tendon_stiffness_N",
             "free_length_m", "sheath_length_m", "tendon_offset_mm",
             "bend_stiffness_Nmm_per_rad", "shaft_gap_load_N", "shaft_stiffness_N_per_mm",
             "crimp_creep_load_N", "crimp_hardening_mm", "handle_speed_deg_s", "tissue_angle_deg",
             "jaw_play_stiffness_Nm_per_rad")
_NON_NEGATIVE = ("jaw_play_deg", "slack_pos_mm", "slack_neg_mm", "sheath_friction",
                 "sheath_wrap_deg", "sheath_drag_N", "idler_friction", "idler_count",
                 "idler_inertia_kgm2", "bend_stiffening_per_rad2", "shaft_gap_mm",
                 "crimp_creep_mm_per_s", "crimp_creep_exponent", "handle_friction_Nm",
                 "tissue_moment_Nmm",
                 "heart_moment_Nmm", "heart_rate_hz")


def node_friction(knob: JawCrimpKnob, curvature_deg: float) -> float:
    """The node's friction share h: capacity = drag + h (T1 + T2), from the lumen's wrap and
    the idlers' bushings. Chosen so that at full slip the node's tension ratio
    (1 + h) / (1 - h) is the whole lumen's exp(mu x wrap) times each idler's
    (1 + f) / (1 - f): about mu x wrap / 2 + idlers x f while small, below 1 always."""
    wrap_rad = math.radians(knob.sheath_wrap_deg + curvature_deg)
    return math.tanh(0.5 * knob.sheath_friction * wrap_rad
                     + knob.idler_count * math.atanh(min(knob.idler_friction, 0.99)))


def knob_from(values: Mapping[str, Any] | JawCrimpKnob, nominal: JawCrimpKnob,
              curvature_deg: float) -> JawCrimpKnob:
    """A checked knob from a dict of overrides (or a knob); bad input is one clear line."""
    if isinstance(values, JawCrimpKnob):
        knob = values
    else:
        names = {f.name for f in dataclasses.fields(JawCrimpKnob)}
        unknown = sorted(set(values) - names)
        if unknown:
            raise PlantLoadError(f"unknown jawcrimp knob constants: {', '.join(unknown)}")
        knob = dataclasses.replace(nominal, **dict(values))
    for name in _POSITIVE:
        value = getattr(knob, name)
        if not (math.isfinite(value) and value > 0.0):
            raise PlantLoadError(f"jawcrimp {name} must be > 0, got {value!r}")
    for name in _NON_NEGATIVE:
        value = getattr(knob, name)
        if not (math.isfinite(value) and value >= 0.0):
            raise PlantLoadError(f"jawcrimp {name} must be >= 0, got {value!r}")
    if not 0.0 < knob.node_share < 1.0:
        raise PlantLoadError(f"jawcrimp node_share must be in (0, 1), got {knob.node_share!r}")
    if not knob.idler_friction < 0.5:
        raise PlantLoadError(f"jawcrimp idler_friction must be < 0.5, got "
                             f"{knob.idler_friction!r}")
    return knob


def knobs_from(knobs: Sequence[Mapping[str, Any] | JawCrimpKnob] | None,
               curvature_deg: float) -> tuple[JawCrimpKnob, JawCrimpKnob]:
    """Both knobs checked (``None``: the nominal pair)."""
    if not (math.isfinite(curvature_deg) and curvature_deg >= 0.0):
        raise PlantLoadError(f"jawcrimp sheath_curvature_deg must be >= 0, got {curvature_deg!r}")
    if knobs is None:
        knobs = NOMINAL_KNOBS
    if len(knobs) != 2:
        raise PlantLoadError(f"jawcrimp takes 2 knobs, got {len(knobs)}")
    return (knob_from(knobs[0], NOMINAL_KNOBS[0], curvature_deg),
            knob_from(knobs[1], NOMINAL_KNOBS[1], curvature_deg))


UNIT_SCATTER: dict[str, float] = {
    "pulley_radius_mm": 0.02,  # moulded drum
    "jaw_play_deg": 0.40,  # spider set and hub bore fit
    "jaw_twist_deg": 0.20,  # spider durometer lot
    "jaw_torque_Nm": 0.20,
    "slack_pos_mm": 0.15,  # rope cut and crimped by hand
    "slack_neg_mm": 0.15,
    "tendon_stiffness_N": 0.10,  # wire-rope lot (steel)
    "free_length_m": 0.20,  # handle assembly, idler positions
    "sheath_length_m": 0.02,  # cut to length
    "node_share": 0.15,  # where the lumen's friction concentrates
    "sheath_friction": 0.15,  # liner and rope surface, lubricant
    "sheath_wrap_deg": 0.10,  # the shaft's lay in the patient
    "sheath_drag_N": 0.20,  # lumen seal, idler bushing preload
    "idler_friction": 0.25,  # bushing fit and grease
    "tendon_offset_mm": 0.05,  # lumen placement in the extrusion
    "bend_stiffness_Nmm_per_rad": 0.15,  # cover polymer lot
    "shaft_gap_mm": 0.25,  # coil pitch and how it was pre-compressed
    "shaft_gap_load_N": 0.20,
    "shaft_stiffness_N_per_mm": 0.15,
    "crimp_creep_mm_per_s": 0.40,  # swage pressure
    "handle_friction_Nm": 0.20,  # knob shaft seal squeeze
    "heart_moment_Nmm": 0.30,  # where the probe lies against the heart
}
"""Unit-to-unit scatter of this plant's constants: the relative half-range of a uniform draw
around the nominal value, per constant a unit draws (:func:`simrig.family.family_member`);
the constants not listed are the product's design."""
