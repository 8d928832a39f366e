"""Units of the product: catheters drawn around each built-in plant's nominal unit, by seed.

A real product's catheters differ: every physical constant scatters from unit to unit (table
``SCATTER``, relative half-range of a uniform draw, per plant), and a lab meets named variants
(``VARIANTS``: a routed handle, a longer or curved sheath, asymmetric slack, a worn catheter, a
noisier current sensor, a stiffer motor). ``family_member(plant, unit, variant)`` returns one
catheter as a :class:`FamilyMember`: the ``module:factory`` spec and parameters
``simrig.plant.load_plant`` takes, plus the drive-side settings of the simulated rig (motor
friction, current sensor) that live outside the plant.

Unit 0 is the nominal unit (no scatter). Units 1-8 are the development set, units 101-108 the
held-out set: tune on the first, report the second. The capstan plant is the development plant,
the lumped plant is held out, the segments plant (written blind in session 9) is held out now,
the coilpipe plant (session 10, written blind) is held out now, the stickslip plant (session 11,
written blind) is held out now, the twistshaft plant (session 12) is held out now, the screwrod
plant (session 13) is held out now, the nitinol plant (session 14, written blind) is held out
now, the helixbelt plant (session 15, written blind) is held out now, the ratestate plant
(session 16, written blind) is held out now, the warmgear plant (session 18, written blind) is
held out now, the archwave plant (session 19, written blind) is held out now (tuned on its
development units in session 20), the jawcrimp plant (session 20, written blind, run untuned, then
tuned on its development units in the same session's second round) is held out, the cyclopebax
plant (session 21, written blind, run untuned, then its sheet constant tuned on its development
units in the same session's second round) is held out, the snakedent plant (session 22, written
blind: rolling vertebrae, detented knobs, run untuned, then its edge reading tuned on its
development units in the same session's second round) is held out (``PLANT_ROLE``); the
planetwist plant (session 23, written blind: a planetary handle stage, twist-coupled strands in
swivel crimps, blood flow on the tip; run untuned, then ours' gain reading made consistent on its
development units in the same session's second round) is held out; the notchclutch plant
(session 24, written blind: a slip clutch in the handle, aramid tendons on a soaking hydrophilic
liner, a notched steel section, a tip rubbing on the wall; run untuned, then traced on its
development units in the same session's second round) is held out; the pronyring plant (session
25, written blind: a viscoelastic Pebax section, a pull ring on a compliant bond, PTFE-lined ropes
along a breathing path; run untuned) is held out from the end of session 25; the wormeyelet
plant (session 26, written blind: a worm-stage handle with a silicone damper, ropes over one
lumen contact, a spacer-disk section whose eyelets the ropes rub; run untuned) is held out from
the end of session 26; the beltbraid plant (session 27, written blind: a belt-driven spring-return
handle, steel ropes with distributed microslip in a braided lumen, a braided shaft whose wire
crossings slip (Preisach), an asymmetrically notched tube; run untuned) is held out from the end
of session 27; the rackgrease plant (session 28, written blind: a rack-and-pinion handle whose
rack cocks in its guide, an eddy-current knob damper, ropes over one capstan contact, a
grease-packed section (Bingham yield and flow), a heavy transducer head under gravity; run
untuned) is registered last and held out from the end of session 28.
``SCATTER`` lives in :mod:`simrig.family_scatter`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from simrig.family_scatter import SCATTER
from simrig.motor import MotorParams
from simrig.plant import Plant, PlantLoadError, load_plant
from simrig.plants.archwave import NOMINAL_KNOBS as ARCHWAVE_KNOBS
from simrig.plants.beltbraid import NOMINAL_KNOBS as BELTBRAID_KNOBS
from simrig.plants.capstan import DEFAULT_KNOBS as CAPSTAN_KNOBS
from simrig.plants.coilpipe import NOMINAL_KNOBS as COILPIPE_KNOBS
from simrig.plants.cyclopebax import NOMINAL_KNOBS as CYCLOPEBAX_KNOBS
from simrig.plants.helixbelt import NOMINAL_KNOBS as HELIXBELT_KNOBS
from simrig.plants.jawcrimp import NOMINAL_KNOBS as JAWCRIMP_KNOBS
from simrig.plants.lumped import NOMINAL_KNOBS as LUMPED_KNOBS
from simrig.plants.nitinol import NOMINAL_KNOBS as NITINOL_KNOBS
from simrig.plants.notchclutch import NOMINAL_KNOBS as NOTCHCLUTCH_KNOBS
from simrig.plants.planetwist import NOMINAL_KNOBS as PLANETWIST_KNOBS
from simrig.plants.pronyring import NOMINAL_KNOBS as PRONYRING_KNOBS
from simrig.plants.rackgrease import NOMINAL_KNOBS as RACKGREASE_KNOBS
from simrig.plants.ratestate import NOMINAL_KNOBS as RATESTATE_KNOBS
from simrig.plants.screwrod import NOMINAL_KNOBS as SCREWROD_KNOBS
from simrig.plants.segments import NOMINAL_KNOBS as SEGMENTS_KNOBS
from simrig.plants.snakedent import NOMINAL_KNOBS as SNAKEDENT_KNOBS
from simrig.plants.stickslip import NOMINAL_KNOBS as STICKSLIP_KNOBS
from simrig.plants.twistshaft import NOMINAL_KNOBS as TWISTSHAFT_KNOBS
from simrig.plants.warmgear import NOMINAL_KNOBS as WARMGEAR_KNOBS
from simrig.plants.wormeyelet import NOMINAL_KNOBS as WORMEYELET_KNOBS
from simrig.rig import DEFAULT_CURRENT_SENSOR

PLANT_SPECS: dict[str, str] = {
    "capstan": "simrig.plants.capstan:make_tendon_sheath_plant",
    "lumped": "simrig.plants.lumped:make_lumped_plant",
    "segments": "simrig.plants.segments:make_segments_plant",
    "coilpipe": "simrig.plants.coilpipe:make_coilpipe_plant",
    "stickslip": "simrig.plants.stickslip:make_stickslip_plant",
    "twistshaft": "simrig.plants.twistshaft:make_twistshaft_plant",
    "screwrod": "simrig.plants.screwrod:make_screwrod_plant",
    "nitinol": "simrig.plants.nitinol:make_nitinol_plant",
    "helixbelt": "simrig.plants.helixbelt:make_helixbelt_plant",
    "ratestate": "simrig.plants.ratestate:make_ratestate_plant",
    "warmgear": "simrig.plants.warmgear:make_warmgear_plant",
    "archwave": "simrig.plants.archwave:make_archwave_plant",
    "jawcrimp": "simrig.plants.jawcrimp:make_jawcrimp_plant",
    "cyclopebax": "simrig.plants.cyclopebax:make_cyclopebax_plant",
    "snakedent": "simrig.plants.snakedent:make_snakedent_plant",
    "planetwist": "simrig.plants.planetwist:make_planetwist_plant",
    "notchclutch": "simrig.plants.notchclutch:make_notchclutch_plant",
    "pronyring": "simrig.plants.pronyring:make_pronyring_plant",
    "wormeyelet": "simrig.plants.wormeyelet:make_wormeyelet_plant",
    "beltbraid": "simrig.plants.beltbraid:make_beltbraid_plant",
    "rackgrease": "simrig.plants.rackgrease:make_rackgrease_plant",  # last: seeds hold
}
PLANT_ROLE = {"capstan": "development", "lumped": "held-out", "segments": "held-out",
              "coilpipe": "held-out", "stickslip": "held-out", "twistshaft": "held-out",
              "screwrod": "held-out", "nitinol": "held-out", "helixbelt": "held-out",
              "ratestate": "held-out", "warmgear": "held-out", "archwave": "held-out",
              "jawcrimp": "held-out", "cyclopebax": "held-out", "snakedent": "held-out",
              "planetwist": "held-out", "notchclutch": "held-out",
              "pronyring": "held-out", "wormeyelet": "held-out",
              "beltbraid": "held-out", "rackgrease": "held-out"}

DEVELOPMENT_UNITS = tuple(range(1, 9))
HELD_OUT_UNITS = tuple(range(101, 109))


_NOMINAL: dict[str, tuple[Any, ...]] = {"capstan": CAPSTAN_KNOBS, "lumped": LUMPED_KNOBS,
                                        "segments": SEGMENTS_KNOBS,
                                        "coilpipe": COILPIPE_KNOBS,
                                        "stickslip": STICKSLIP_KNOBS,
                                        "twistshaft": TWISTSHAFT_KNOBS,
                                        "screwrod": SCREWROD_KNOBS,
                                        "nitinol": NITINOL_KNOBS,
                                        "helixbelt": HELIXBELT_KNOBS,
                                        "ratestate": RATESTATE_KNOBS,
                                        "warmgear": WARMGEAR_KNOBS,
                                        "archwave": ARCHWAVE_KNOBS,
                                        "jawcrimp": JAWCRIMP_KNOBS,
                                        "cyclopebax": CYCLOPEBAX_KNOBS,
                                        "snakedent": SNAKEDENT_KNOBS,
                                        "planetwist": PLANETWIST_KNOBS,
                                        "notchclutch": NOTCHCLUTCH_KNOBS,
                                        "pronyring": PRONYRING_KNOBS,
                                        "wormeyelet": WORMEYELET_KNOBS,
                                        "beltbraid": BELTBRAID_KNOBS,
                                        "rackgrease": RACKGREASE_KNOBS}


@dataclass(frozen=True)
class Variant:
    """A named deviation a lab meets: per-knob factors, plant effects, rig settings."""

    description: str
    factors: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    """Per plant, constant -> factor on both knobs (after the scatter)."""
    absolute: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    """Per plant, constant -> value on both knobs."""
    effects: Mapping[str, Mapping[str, float]] = field(default_factory=dict)
    motor: Mapping[str, float] = field(default_factory=dict)
    """Factors on :class:`simrig.motor.MotorParams` fields."""
    current_sensor: Mapping[str, float] = field(default_factory=dict)
    """Values for :class:`simrig.current_sensor.CurrentSensor` keywords."""


VARIANTS: dict[str, Variant] = {
    "routed-handle": Variant(
        "tendons wrap over guide pins in the handle before the sheath",
        absolute={"capstan": {"routing_wrap_deg": 90.0}},
        factors={"lumped": {"guide_wrap_deg": 3.0}},
    ),
    "long-sheath": Variant(
        "30 % longer sheath (more wrap, more tendon to stretch)",
        factors={p: {"sheath_length_m": 1.3, "sheath_wrap_deg": 1.3} for p in _NOMINAL},
    ),
    "curved-sheath": Variant(
        "sheath laid in a 120 deg curve",
        effects={p: {"sheath_curvature_deg": 120.0} for p in _NOMINAL},
    ),
    "asymmetric-slack": Variant(
        "one tendon of each pair tensioned tighter at assembly",
        factors={p: {"slack_pos_mm": 1.3, "slack_neg_mm": 0.75} for p in _NOMINAL},
    ),
    "worn": Variant(
        "worn catheter: lumen coating and links rubbed, more friction everywhere",
        factors={
            "capstan": {"sheath_friction": 1.3, "sheath_drag_N": 1.5, "bend_friction_Nm": 1.5,
                        "handle_friction_Nm": 1.5},
            "lumped": {"sheath_friction": 1.3, "sheath_drag_N": 1.5, "bend_friction_Nm": 1.5,
                       "handle_friction_Nm": 1.5},
            "segments": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                         "bend_hysteresis_Nm": 1.5, "handle_friction_Nm": 1.5},
            "coilpipe": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                         "viscous_N_s_per_mm": 1.5, "handle_friction_Nm": 1.5},
            "stickslip": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                          "handle_friction_Nm": 1.5},
            "twistshaft": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                           "handle_friction_Nm": 1.5},
            "screwrod": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                         "handle_friction_Nm": 1.5, "thread_friction": 1.2},
            "nitinol": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                        "handle_friction_Nm": 1.5, "film_damping_N_s_per_mm": 1.5},
            "helixbelt": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                          "handle_friction_Nm": 1.5, "braid_friction_Nm": 1.5},
            "ratestate": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                          "handle_friction_Nm": 1.5, "link_friction": 1.5},
            "warmgear": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                         "handle_friction_Nm": 1.5, "mesh_friction": 1.5,
                         "gear_play_deg": 1.5},
            "archwave": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                         "handle_friction_Nm": 1.5, "wave_drag_Nm": 1.5},
            "jawcrimp": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                         "handle_friction_Nm": 1.5, "idler_friction": 1.5},
            "cyclopebax": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                           "handle_friction_Nm": 1.5, "mesh_friction": 1.3},
            "snakedent": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                          "handle_friction_Nm": 1.5, "joint_friction_mm": 1.5},
            "planetwist": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                           "handle_friction_Nm": 1.5, "swivel_friction_Nmm": 1.5,
                           "carrier_play_deg": 1.5},
            "notchclutch": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                            "handle_friction_Nm": 1.5, "tissue_friction_Nmm": 1.5},
            "pronyring": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                          "handle_friction_Nm": 1.5, "ring_tilt_Nmm_per_rad": 1.0 / 1.3},
            "wormeyelet": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                           "handle_friction_Nm": 1.5, "worm_friction": 1.5,
                           "worm_play_deg": 1.5},
            "beltbraid": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                          "handle_friction_Nm": 1.5, "belt_creep_per_Nm": 1.5,
                          "braid_hold_N": 1.3},
            "rackgrease": {"sheath_friction": 1.3, "sheath_drag_N": 1.5,
                           "handle_friction_Nm": 1.5, "guide_friction": 1.3,
                           "section_yield_Nmm": 1.5},
        },
    ),
    "steel-tendon": Variant(
        "stiffer (steel) tendons on a larger moment arm: the tip releases at about its loaded "
        "slope, as on the real TEE probe, and the backlash is smaller",
        factors={p: {"tendon_stiffness_N": 2.5, "tendon_offset_mm": 1.4, "sheath_friction": 1.2}
                 for p in _NOMINAL},
    ),
    "compliant-tendon": Variant(
        "compliant (polymer or thin) tendons: stretch takes a larger share of the draw-in while "
        "loading than while releasing, so the tip releases steeper than it loads (outside the "
        "real TEE probe); on capstan exactly the development plant's nominal unit before session 5",
        factors={"capstan": {"tendon_stiffness_N": 0.5, "tendon_offset_mm": 1.0 / 1.4,
                             "sheath_friction": 1.0 / 1.4, "slack_pos_mm": 1.0 / 1.2,
                             "slack_neg_mm": 1.0 / 1.2},
                 "lumped": {"tendon_stiffness_N": 0.4},
                 "segments": {"tendon_stiffness_N": 0.4},
                 "coilpipe": {"tendon_stiffness_N": 0.4},
                 "stickslip": {"tendon_stiffness_N": 0.4},
                 "twistshaft": {"tendon_stiffness_N": 0.4},
                 "screwrod": {"tendon_stiffness_N": 0.4},
                 "nitinol": {"tendon_stiffness_N": 0.4},
                 "helixbelt": {"tendon_stiffness_N": 0.4},
                 "ratestate": {"tendon_stiffness_N": 0.4},
                 "warmgear": {"tendon_stiffness_N": 0.4},
                 "archwave": {"tendon_stiffness_N": 0.4},
                 "jawcrimp": {"tendon_stiffness_N": 0.4},
                 "cyclopebax": {"tendon_stiffness_N": 0.4},
                 "snakedent": {"tendon_stiffness_N": 0.4},
                 "planetwist": {"tendon_stiffness_N": 0.4},
                 "notchclutch": {"tendon_stiffness_N": 0.4},
                 "pronyring": {"tendon_stiffness_N": 0.4},
                 "wormeyelet": {"tendon_stiffness_N": 0.4},
                 "beltbraid": {"tendon_stiffness_N": 0.4},
                 "rackgrease": {"tendon_stiffness_N": 0.4}},
    ),
    "noisy-sensor": Variant(
        "drive with a noisier current measurement (10 mA noise, 2 Hz spikes, 5 ms lag)",
        current_sensor={"noise_A": 0.010, "spike_rate_hz": 2.0, "lag_s": 0.005},
    ),
    "motor-friction": Variant(
        "another motor/gearbox: three times the Coulomb friction, twice the viscous",
        motor={"friction_Nm": 3.0, "viscous_Nm_s_rad": 2.0},
    ),
}


@dataclass(frozen=True)
class FamilyMember:
    """One catheter of the family: how to build its plant and how its drives differ."""

    plant: str
    unit: int
    variant: str | None
    spec: str
    params: dict[str, Any]
    motor: MotorParams
    current_sensor: dict[str, float]

    @property
    def label(self) -> str:
        return f"{self.plant} unit {self.unit}" + (f" {self.variant}" if self.variant else "")

    @property
    def unit_set(self) -> str:
        """``nominal``, ``development`` or ``held-out``."""
        return unit_set(self.unit)

    def build(self) -> Plant:
        """A fresh plant of this unit."""
        return load_plant(self.spec, self.params)

    def rig_kwargs(self) -> dict[str, Any]:
        """Keywords for :class:`simrig.rig.SimRig` (``motor``, ``current_sensor``)."""
        return {"motor": self.motor, "current_sensor": dict(self.current_sensor)}


def unit_set(unit: int) -> str:
    if unit == 0:
        return "nominal"
    if unit in DEVELOPMENT_UNITS:
        return "development"
    if unit in HELD_OUT_UNITS:
        return "held-out"
    return "other"


def family_member(plant: str = "capstan", unit: int = 0, variant: str | None = None,
                  seed: int = 0) -> FamilyMember:
    """Catheter ``unit`` of ``plant`` (0: nominal), optionally a named ``variant``.

    The draw depends only on (plant, unit, seed): the same arguments give the same catheter.
    """
    if plant not in PLANT_SPECS:
        raise PlantLoadError(f"unknown plant {plant!r}; known: {', '.join(PLANT_SPECS)}")
    if isinstance(unit, bool) or not isinstance(unit, int) or unit < 0:
        raise PlantLoadError(f"unit must be an integer >= 0, got {unit!r}")
    if variant is not None and variant not in VARIANTS:
        raise PlantLoadError(f"unknown variant {variant!r}; known: {', '.join(VARIANTS)}")
    rng = np.random.default_rng([list(PLANT_SPECS).index(plant), unit, seed])
    knobs: list[dict[str, float]] = []
    for nominal in _NOMINAL[plant]:
        values = dataclasses.asdict(nominal)
        for name, half_range in SCATTER[plant].items():
            draw = rng.uniform(-1.0, 1.0)  # drawn for unit 0 too: the sequence stays aligned
            if unit != 0:
                values[name] *= 1.0 + half_range * draw
        knobs.append(values)
    effects: dict[str, float] = {}
    motor = MotorParams()
    sensor = dict(DEFAULT_CURRENT_SENSOR)
    if variant is not None:
        v = VARIANTS[variant]
        for values in knobs:
            for name, factor in v.factors.get(plant, {}).items():
                values[name] *= factor
            values.update(v.absolute.get(plant, {}))
        effects.update(v.effects.get(plant, {}))
        motor = dataclasses.replace(motor, **{k: getattr(motor, k) * f
                                              for k, f in v.motor.items()})
        sensor.update(v.current_sensor)
    params: dict[str, Any] = {"knobs": knobs, **effects}
    return FamilyMember(plant, unit, variant, PLANT_SPECS[plant], params, motor, sensor)


def family(plant: str, units: int, held_out: bool = False, variants: bool = False,
           seed: int = 0) -> list[FamilyMember]:
    """The nominal unit, then ``units`` units of the chosen set, then (optionally) every named
    variant of the nominal unit."""
    pool = HELD_OUT_UNITS if held_out else DEVELOPMENT_UNITS
    if not 0 <= units <= len(pool):
        raise PlantLoadError(f"units must be in 0..{len(pool)}, got {units}")
    members = [family_member(plant, 0, seed=seed)]
    members += [family_member(plant, u, seed=seed) for u in pool[:units]]
    if variants:
        members += [family_member(plant, 0, v, seed=seed) for v in VARIANTS]
    return members


def make_family_plant(plant: str = "capstan", unit: int = 0, variant: str | None = None,
                      seed: int = 0) -> Plant:
    """A ``module:factory`` entry for one family member's plant
    (``simrig.family:make_family_plant`` with ``{"plant": "lumped", "unit": 101}``), so that
    anything taking a plant factory (config ``sim.plant``, ``tsmd datasheet``, the benchmarks)
    can draw units of either plant. The member's motor and sensor variants are not applied here:
    they belong to the rig (:meth:`FamilyMember.rig_kwargs`)."""
    return family_member(plant, unit, variant, seed).build()
