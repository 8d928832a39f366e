"""The plants the cross-plant self-test knows by name, each effect in the plant's own physics.

A preset is a plant factory with fixed parameters, what to fit when it is the simulator, and how
each self-test case puts its effect into that plant (its own keywords, or factors on a family
unit's knob constants); a case the plant has no physics for is not run. The strengths are sized
before any diagnosis, by the tip RMSE the effect moves (docs/gap.md, per plant's session).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

from simrig.family import PLANT_SPECS, family_member
from simrig.plant import load_plant
from tsmd.gap.errors import GapError
from tsmd.gap.fit import ParamSpec
from tsmd.gap.selftest import BUILTIN_FIT_SPECS, BUILTIN_PLANT, EFFECTS

OTHER_CAPSTAN_KNOBS: tuple[dict[str, float], ...] = (
    {"sheath_friction": 0.12, "sheath_wrap_deg": 300.0, "slack_pos_mm": 1.2, "slack_neg_mm": 1.5,
     "tendon_stiffness_N": 5500.0, "bend_friction_Nm": 0.0012,
     "bend_stiffness_Nm_per_rad": 0.009, "handle_friction_Nm": 0.02, "routing_wrap_deg": 180.0,
     "sheath_drag_N": 0.3, "pulley_radius_mm": 5.0},
    {"sheath_friction": 0.15, "sheath_wrap_deg": 330.0, "slack_pos_mm": 1.0, "slack_neg_mm": 1.4,
     "tendon_stiffness_N": 5000.0, "bend_friction_Nm": 0.001,
     "bend_stiffness_Nm_per_rad": 0.008, "handle_friction_Nm": 0.018, "routing_wrap_deg": 180.0,
     "sheath_drag_N": 0.25, "pulley_radius_mm": 5.0},
)
"""The stand-in 'other catheter' until an independently formulated plant lands: the capstan
plant with strongly different physics (half the sheath friction over less wrap, a routed handle,
smaller pulley, more drag, stiffer and more frictional bending joints, half the slack). Its
tendon stiffness stays near the default (5000-5500 N against 6000 N): a tendon twice as
compliant *is* the compliance effect, so a base that differs along one of the six effect axes
would make the self-test's truth ambiguous ("none" data that need compliance)."""


LUMPED_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling": 1.0},
    "rate": {"viscous_N_s_per_m": 20.0},
    "compliance": {"tendon_compliance": 1.0},
    "curvature": {"sheath_curvature_deg": 120.0},
    "creep": {"creep_compliance_mm_per_N": 0.05},
}
"""The self-test effects in the lumped plant's own physics (its keywords), at strengths that move
the tip about as much as the capstan plant's do (2 x 120 s of the experiment motion, unit 1,
noise-free, effect on minus off, capstan / lumped): coupling 1.5 / 1.6 deg, rate 1.7 / 1.9 deg,
compliance 9.8 / 7.6 deg, curvature 12.0 / 8.5 deg, creep 0.35 / 0.42 deg (docs/gap.md)."""

SEGMENTS_BASE: dict[str, Any] = {"coupling": 0.0}
"""The segments plant couples its two planes by default; its "none" units and its simulator have
the coupling off, as the other plants' have every effect off."""

SEGMENTS_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling": 1.0},
    "rate": {"viscous_N_s_per_m": 90.0},
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The self-test effects in the segments plant's own physics, sized like the lumped ones (tip
RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion at 50 Hz; capstan
coupling 1.47, rate 1.70 deg): its nominal coupling 1.40 deg, lumen drag 90 N s/m (nominal 2)
1.72 deg, a 120 deg bend 6.91 deg. It has no creep: that case is not run on it."""

SEGMENTS_KNOB_EFFECTS: dict[str, dict[str, float]] = {"compliance": {"tendon_stiffness_N": 0.5}}
"""Compliance on segments: the unit's tendon EA halved (no keyword of its own; the other plants'
``tendon_compliance`` 1.0 is exactly that, docs/gap.md). Tip moved 6.42 deg (unit 1)."""


COILPIPE_BASE: dict[str, Any] = {"coupling_mm_per_rad2": 0.0}
"""The coilpipe plant shortens a tendon's path with the other plane's bend by default (0.25
mm/rad^2); its "none" units and its simulator have that off. What stays on is base physics: the
shaft's compression under all four tensions (a load coupling of both knobs), LuGre friction
with Stribeck and viscous terms (a rate dependence of its own) and the tip's relaxing stiffness
(2 s: a creep of its own); docs/gap.md "Session 11"."""

COILPIPE_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"coupling_mm_per_rad2": 0.55},
    "curvature": {"sheath_curvature_deg": 120.0},
}
"""The self-test effects in the coilpipe plant's own keywords, sized like the others before any
diagnosis (tip RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion at
50 Hz): path coupling 0.55 mm/rad^2 1.51 deg, a 120 deg bend 5.14 deg."""

COILPIPE_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"viscous_N_s_per_mm": 8.0},
    "compliance": {"tendon_stiffness_N": 0.5},
    "creep": {"bend_creep_time_s": 2.0},
}
"""Coilpipe effects without a keyword, as factors on the unit's knob constants (same sizing):
lumen viscosity x8 1.56 deg, tendon EA halved 4.47 deg, the tip cover relaxing twice as slowly
(2 -> 4 s, its one creep branch) 0.58 deg."""


STICKSLIP_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The stickslip plant's one effect keyword: a 120 deg sheath bend moves its tip by 1.99 deg (tip
RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion at 50 Hz; the
other plants' 5-12 deg). Its knobs' coupling (each tendon rubs round the whole bent section) is
base physics with no constant of its own: that case is not run on it (as segments' creep)."""

STICKSLIP_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"creep_fast_share": 5.0},
    "compliance": {"tendon_stiffness_N": 0.5},
    "creep": {"creep_slow_share": 1.5},
}
"""Stickslip effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion): its only rate-dependent physics is the tendons' relaxation, so rate is the fast
(0.5 s) Maxwell branch five times as stiff, 1.11 deg (x3: 0.65; the protocol's 20 against 80
deg/s loops then differ by 0.36 / 0.16 deg RMS, the nominal unit's own 0.16 / 0.09); creep the
slow (12 s) branch 1.5 times as stiff, 0.38 deg (the other plants' creep 0.35-0.42 deg); the
tendon EA halved, 3.73 deg. "None" is the nominal physics as written: relaxing tendons,
stick-slip, the brake and the bend's coupling are its base (docs/gap.md "Session 12")."""


TWISTSHAFT_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The twistshaft plant's one effect keyword: a 120 deg sheath bend, 12.8 deg of tip (tip RMSE
effect on minus off, unit 1, noise-free, 120 s of the experiment motion at 50 Hz). The plant is
quasi-static with no load relaxation: no rate or creep physics, those cases are not run. Its
warm-up (24 -> 37 C in 60 s from every reset) is base physics: every recording, the data
sheet's included, starts at insertion (docs/gap.md "Session 13")."""

SCREWROD_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The screwrod plant's one effect keyword: a 120 deg sheath bend (adds to every tendon's wrap).
Its cross-coupling (both planes' bends add to each tendon's wrap) has no constant of its own and
it has no speed-dependent physics (Iwan contacts, a Norton creep in time): coupling and rate are
not run. Its tendons' creep is base physics as well (every recording, the reference units'
included, starts uncreeped at insertion): "none" is the nominal physics (docs/gap.md "Session
14")."""

SCREWROD_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "compliance": {"tendon_stiffness_N": 0.5},
    "creep": {"creep_time_s": 0.07},
}
"""Screwrod effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, the plant stepped at 4 ms): the braid's EA halved, 3.97 deg; its tendons creeping 14
times as fast (0.07 x the creep time: 17 s at 15 N, a braid not heat-set), 0.37 deg (the base
creep alone 0.03 deg; the other plants' creep 0.35-0.42 deg). The 120 deg bend: 1.41 deg."""

SCREWROD_MAX_STEP_S = 0.004
"""The screwrod plant holds its tip to 0.2 deg at steps up to 4 ms (its tests); at 20 ms its
walled knob's Newton step overshoots (torque spikes of hundreds of N m, tip 10 deg off)."""


NITINOL_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The nitinol plant's one effect keyword: a 120 deg sheath bend (adds to every lumen's wrap),
1.61 deg of tip (tip RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion
at 50 Hz). Its planes' coupling (one superelastic spine for both planes; the bend adds wrap) has
no constant of its own and nothing in it drifts in time: coupling and creep are not run. The
lubricant film's speed-dependent friction is base physics; "none" is the nominal physics
(docs/gap.md "Session 15")."""

NITINOL_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"film_damping_N_s_per_mm": 5.0},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Nitinol effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion): the lubricant film five times as viscous, 1.43 deg (x3 0.73, x8 2.48; the others'
rate 1.1-1.9 deg); the wire rope's EA halved, 8.27 deg. Its physics hold at 20 ms steps (tip
0.03 deg RMS from 4 ms ones, unit 1): no finer stepping."""


HELIXBELT_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The helixbelt plant's one effect keyword: a 120 deg sheath bend (added to the shaft's lay),
0.05 deg of tip (tip RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment motion
at 50 Hz; 0.22 deg at most): its tendons run in a helix, whose wrap and length barely change
with the shaft's curve. It is quasi-static with nothing that drifts in time and nothing speed-
dependent at the tip (the knob seal's friction saturates at 2 deg/s, on the motor only): rate
and creep are not run. "None" is the nominal physics as written (docs/gap.md "Session 15")."""

HELIXBELT_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"plane_error_deg": 2.2},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Helixbelt effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion): the helix's phase error at the tip (each plane bends out of its knob's plane, the
planes' cross-coupling) 2.2 times the unit's, 1.51 deg (x2 1.26, x2.5 1.89, x3 2.52; the others'
coupling 1.5 deg); the rope's EA halved, 2.03 deg. Its physics hold at 20 ms steps (tip 0.0005
deg RMS from 4 ms ones, unit 1): no finer stepping."""


RATESTATE_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The ratestate plant's one effect keyword: a 120 deg sheath bend (mid-shaft, adds to every
lumen contact's wrap), 1.94 deg of tip (tip RMSE effect on minus off, unit 1, noise-free, 120 s
of the experiment motion at 50 Hz). Its planes' coupling (both planes' bend adds wrap to every
tendon's distal contacts) has no constant of its own (``bend_lumen_friction`` rubs the own
plane's bend as well), and nothing moves at a held knob (contact ageing raises friction, it
moves no tendon): coupling and creep are not run. "None" is the nominal physics as written
(docs/gap.md "Session 16, round 2")."""

RATESTATE_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"ageing_b": 10.0},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Ratestate effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, the plant stepped at 4 ms): its only speed-dependent physics is the contacts'
rate-and-state friction, so rate is the state coefficient b ten times the unit's, 1.31 deg (x8
1.06, x11 1.59; the others' rate 1.1-1.9 deg; it makes the contacts stick-slip, whose events
move with the step: 0.9 deg RMS between 4 and 1 ms steps); the rope's EA halved, 3.74 deg."""

RATESTATE_MAX_STEP_S = 0.004
"""The nominal ratestate unit's tip lies within 0.08 deg (0.005 RMS) of 1 ms steps at 4 ms steps,
0.72 deg (0.05 RMS) at 20 ms (unit 1, 120 s of the experiment motion)."""


TWISTSHAFT_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "coupling": {"lumen_angle_error_deg": 4.5},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Twistshaft effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion): its lumens sit off their planes (1.5 deg) and the shaft's twist turns the planes, a
coupling of its base; the case puts the lumens 4.5 times as far off, 1.53 deg (the others'
coupling 1.5 deg); the tendon EA halved, 3.59 deg."""


WARMGEAR_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 60.0}}
"""The warmgear plant's one effect keyword: a 60 deg sheath bend (added to the shaft contact's
wrap), 2.10 deg of tip (tip RMSE effect on minus off, unit 1, noise-free, 120 s of the experiment
motion at 50 Hz, 4 ms steps; unit 2 2.90). The others' 120 deg moves it 15.9 deg (20 ms steps:
90 deg 10.8, 75 deg 3.63): its lumped contact's friction x wrap reaches the plant's 0.95 cap
once the film is squeezed, outside the others' 1.1-12.8 deg (30 deg 0.79, 45 deg 1.34). Its
planes' coupling (the section's total bend, both planes, is the wrap of the tendons' distal
contact) has no constant of its own (``bend_wrap_share`` rubs the own plane's bend as well: 0.5
-> 1.0 moves the tip 0.64 deg), and nothing creeps under load: coupling and creep are not run.
The shaft's warm-up (slack shrinking, section softening after insertion) is base physics: every
recording, the reference units' included, starts at insertion; with three times the thermal
mismatch it moves the tip 1.29 deg over the motion but drifts 0.0 deg / 0.6 mA over a held
loaded dwell beyond an unloaded one (protocol, unit 1), below one sample's noise. "None" is
the nominal physics as written. Sized on the plant's re-tuned constants (s18-plant a6c2b95;
docs/gap.md "Session 18")."""

WARMGEAR_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "rate": {"film_viscous_N_s_per_mm": 2.0},
    "compliance": {"tendon_stiffness_N": 0.5},
}
"""Warmgear effects as factors on the unit's knob constants, sized before any diagnosis (same
criterion, 4 ms steps): its only speed-dependent physics is the sheath film's shear, so rate is
the film twice as viscous, 1.63 deg (unit 2 1.62; at 20 ms x1.5 0.81, x2.5 2.39, x3 3.14; the
others' rate 1.1-1.9 deg), whose protocol fast-minus-slow contrast is 0.69 deg / 1.6 mA (unit
1; detectable); the rope's EA halved, 3.44 deg (unit 2 3.09)."""

WARMGEAR_MAX_STEP_S = 0.004
"""The nominal warmgear unit's tip lies within 0.10 deg (0.015 RMS) of 1 ms steps at 4 ms
steps, 0.50 deg (0.088 RMS) at 20 ms (unit 1, 120 s of the experiment motion): as ratestate."""


ARCHWAVE_EFFECTS: dict[str, dict[str, float]] = {"curvature": {"sheath_curvature_deg": 120.0}}
"""The archwave plant's one effect keyword: a 120 deg sheath bend (added to the path's arch, in
its plane: wrap for every tendon, path slack by lumen), 4.47 / 3.58 deg of tip (tip RMSE effect
on minus off, units 1 / 2, noise-free, 120 s of the experiment motion at 50 Hz). Its planes'
coupling has no constant of its own (``section_wrap_share`` and ``bend_stiffening_per_rad2``
take the own plane's bend as well: x2 / x3 move the tip 0.22 / 0.64 deg); nothing at the tip
depends on speed (the wave generator's viscous and Coulomb drags, saturated at 2 deg/s, are on
the motor: x10 viscous moves the tip 0.000 deg, the current 15 mA RMS) or drifts at a held knob
(Bouc-Wen is rate-independent; the warming torque constant moves the current only): coupling,
rate and creep are not run. "None" is the nominal physics as written (docs/gap.md "Session
20")."""

ARCHWAVE_KNOB_EFFECTS: dict[str, dict[str, float]] = {
    "compliance": {"tendon_stiffness_N": 0.5, "coil_compliance_mm_per_N": 2.0},
}
"""Compliance on archwave as factors on the unit's knob constants, sized before any diagnosis
(same criterion): the tendon's whole compliance doubled, the rope's EA halved and its coil
sheath's shortening per newton doubled (the coil is 60 % of it: the EA halved alone 1.30 / 1.46
deg, below every other plant's 2.0-9.8), 2.89 / 2.91 deg (units 1 / 2)."""

ARCHWAVE_MAX_STEP_S = 0.004
"""The archwave unit's tip lies 0.052 deg RMS (0.66 max) from 0.5 ms steps at 20 ms steps,
0.028 (0.34) at 4 ms (unit 1; unit 2 0.051 / 0.028): the gear's one-step lag, as ratestate."""


@dataclass(frozen=True)
class PlantSpec:
    """A plant as ``module:factory`` + fixed keyword parameters + what to fit as a simulator.

    ``family`` names a :mod:`simrig.family` plant: its units (scatter by unit number: 1-8
    development, 101-108 held out) are built from the family's draw; otherwise a unit is the
    factory's own ``unit_variation``/``seed``. ``effects`` maps a self-test case to the plant's
    effect keywords (default: :data:`tsmd.gap.selftest.EFFECTS`, the capstan plant's).
    """

    factory: str
    params: dict[str, Any] = field(default_factory=dict)
    fit: tuple[ParamSpec, ...] = ()
    name: str = ""
    family: str = ""
    effects: dict[str, dict[str, float]] | None = None
    knob_effects: dict[str, dict[str, float]] = field(default_factory=dict)
    """Case -> factors on every knob's constants (a family unit's), for an effect the plant has
    no keyword for."""
    max_step_s: float = 0.0
    """Longest step the plant's physics holds at as data (0: the recording's own step); a
    recording at a coarser rate is made by stepping it finer and sampling (a real catheter is
    continuous; its recorder only samples it)."""

    def build(self, **extra: Any) -> Any:
        return load_plant(self.factory, {**self.params, **extra})

    def supports(self, case: str) -> bool:
        """Whether the plant can put this case's effect in its own physics (the sensor lag is
        the rig's, every plant has it)."""
        return (self.effects is None or case in ("none", "sensor") or case in self.effects
                or case in self.knob_effects)

    def case_effects(self, case: str) -> dict[str, float]:
        if self.effects is None:
            return dict(EFFECTS[case][0])
        return dict(self.effects.get(case, {}))

    def build_unit(self, unit: int, unit_variation: float, case: str = "none",
                   **effects: float) -> Any:
        """Catheter ``unit`` of this plant with ``effects`` (and ``case``'s knob factors)."""
        if self.family:
            member = family_member(self.family, unit)
            params = {**member.params, **self.params, **effects}
            factors = self.knob_effects.get(case, {})
            if factors:
                params["knobs"] = [{k: v * factors.get(k, 1.0) for k, v in knob.items()}
                                   for knob in member.params["knobs"]]
            return load_plant(member.spec, params)
        return self.build(unit_variation=unit_variation, seed=unit, **effects)


PRESETS: dict[str, PlantSpec] = {
    "capstan": PlantSpec(BUILTIN_PLANT, {}, BUILTIN_FIT_SPECS, "capstan"),
    "capstan-other": PlantSpec(BUILTIN_PLANT, {"knobs": [dict(k) for k in OTHER_CAPSTAN_KNOBS]},
                               BUILTIN_FIT_SPECS, "capstan-other"),
    "lumped": PlantSpec(PLANT_SPECS["lumped"], {}, (), "lumped", family="lumped",
                        effects=LUMPED_EFFECTS),
    "segments": PlantSpec(PLANT_SPECS["segments"], dict(SEGMENTS_BASE), (), "segments",
                          family="segments", effects=SEGMENTS_EFFECTS,
                          knob_effects=SEGMENTS_KNOB_EFFECTS),
    "coilpipe": PlantSpec(PLANT_SPECS["coilpipe"], dict(COILPIPE_BASE), (), "coilpipe",
                          family="coilpipe", effects=COILPIPE_EFFECTS,
                          knob_effects=COILPIPE_KNOB_EFFECTS),
    "stickslip": PlantSpec(PLANT_SPECS["stickslip"], {}, (), "stickslip", family="stickslip",
                           effects=STICKSLIP_EFFECTS, knob_effects=STICKSLIP_KNOB_EFFECTS),
    "twistshaft": PlantSpec(PLANT_SPECS["twistshaft"], {}, (), "twistshaft", family="twistshaft",
                            effects=TWISTSHAFT_EFFECTS, knob_effects=TWISTSHAFT_KNOB_EFFECTS),
    "screwrod": PlantSpec(PLANT_SPECS["screwrod"], {}, (), "screwrod", family="screwrod",
                          effects=SCREWROD_EFFECTS, knob_effects=SCREWROD_KNOB_EFFECTS,
                          max_step_s=SCREWROD_MAX_STEP_S),
    "nitinol": PlantSpec(PLANT_SPECS["nitinol"], {}, (), "nitinol", family="nitinol",
                         effects=NITINOL_EFFECTS, knob_effects=NITINOL_KNOB_EFFECTS),
    "helixbelt": PlantSpec(PLANT_SPECS["helixbelt"], {}, (), "helixbelt", family="helixbelt",
                           effects=HELIXBELT_EFFECTS, knob_effects=HELIXBELT_KNOB_EFFECTS),
    "ratestate": PlantSpec(PLANT_SPECS["ratestate"], {}, (), "ratestate", family="ratestate",
                           effects=RATESTATE_EFFECTS, knob_effects=RATESTATE_KNOB_EFFECTS,
                           max_step_s=RATESTATE_MAX_STEP_S),
    "warmgear": PlantSpec(PLANT_SPECS["warmgear"], {}, (), "warmgear", family="warmgear",
                          effects=WARMGEAR_EFFECTS, knob_effects=WARMGEAR_KNOB_EFFECTS,
                          max_step_s=WARMGEAR_MAX_STEP_S),
    "archwave": PlantSpec(PLANT_SPECS["archwave"], {}, (), "archwave", family="archwave",
                          effects=ARCHWAVE_EFFECTS, knob_effects=ARCHWAVE_KNOB_EFFECTS,
                          max_step_s=ARCHWAVE_MAX_STEP_S),
}
"""Named plants for ``--data-plant``/``--sim-plant``."""


def parse_plant_spec(text: str) -> PlantSpec:
    """A preset name, or ``module:factory`` optionally followed by ``@`` and a JSON object."""
    text = text.strip()
    if text in PRESETS:
        return PRESETS[text]
    factory, _, raw = text.partition("@")
    if ":" not in factory:
        raise GapError(f"plant {text!r}: give a preset ({', '.join(PRESETS)}) or "
                       "module:factory[@{json parameters}]")
    params: dict[str, Any] = {}
    if raw:
        try:
            loaded = json.loads(raw)
        except json.JSONDecodeError as exc:
            raise GapError(f"plant {text!r}: parameters after '@' are not JSON: {exc}") from None
        if not isinstance(loaded, dict):
            raise GapError(f"plant {text!r}: parameters after '@' must be a JSON object")
        params = loaded
    load_plant(factory, params)  # fail early, with the loader's message
    return PlantSpec(factory, params, (), text)
