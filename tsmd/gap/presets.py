"""The plants the cross-plant self-test knows by name, each effect in the plant's own physics.

A preset is a plant factory with fixed parameters, what to fit when it is the simulator, and how
each self-test case puts its effect into that plant (its own keywords, or factors on a family
unit's knob constants, in :mod:`tsmd.gap.preset_effects` and, for the plants added since
session 22, :mod:`tsmd.gap.preset_effects_late`); a case the plant has no physics for
is not run.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

from simrig.family import PLANT_SPECS, family_member
from simrig.plant import load_plant
from tsmd.gap.errors import GapError
from tsmd.gap.fit import ParamSpec
from tsmd.gap.preset_effects import (
    ARCHWAVE_EFFECTS,
    ARCHWAVE_KNOB_EFFECTS,
    ARCHWAVE_MAX_STEP_S,
    COILPIPE_BASE,
    COILPIPE_EFFECTS,
    COILPIPE_KNOB_EFFECTS,
    HELIXBELT_EFFECTS,
    HELIXBELT_KNOB_EFFECTS,
    JAWCRIMP_EFFECTS,
    JAWCRIMP_KNOB_EFFECTS,
    JAWCRIMP_MAX_STEP_S,
    LUMPED_EFFECTS,
    NITINOL_EFFECTS,
    NITINOL_KNOB_EFFECTS,
    RATESTATE_EFFECTS,
    RATESTATE_KNOB_EFFECTS,
    RATESTATE_MAX_STEP_S,
    SCREWROD_EFFECTS,
    SCREWROD_KNOB_EFFECTS,
    SCREWROD_MAX_STEP_S,
    SEGMENTS_BASE,
    SEGMENTS_EFFECTS,
    SEGMENTS_KNOB_EFFECTS,
    STICKSLIP_EFFECTS,
    STICKSLIP_KNOB_EFFECTS,
    TWISTSHAFT_EFFECTS,
    TWISTSHAFT_KNOB_EFFECTS,
    WARMGEAR_EFFECTS,
    WARMGEAR_KNOB_EFFECTS,
    WARMGEAR_MAX_STEP_S,
)
from tsmd.gap.preset_effects_late import (
    BELTBRAID_EFFECTS,
    BELTBRAID_KNOB_EFFECTS,
    BELTBRAID_MAX_STEP_S,
    CYCLOPEBAX_EFFECTS,
    CYCLOPEBAX_KNOB_EFFECTS,
    CYCLOPEBAX_MAX_STEP_S,
    NOTCHCLUTCH_EFFECTS,
    NOTCHCLUTCH_KNOB_EFFECTS,
    NOTCHCLUTCH_MAX_STEP_S,
    PLANETWIST_EFFECTS,
    PLANETWIST_KNOB_EFFECTS,
    PLANETWIST_MAX_STEP_S,
    PRONYRING_EFFECTS,
    PRONYRING_KNOB_EFFECTS,
    PRONYRING_MAX_STEP_S,
    RACKGREASE_EFFECTS,
    RACKGREASE_KNOB_EFFECTS,
    RACKGREASE_MAX_STEP_S,
    SNAKEDENT_EFFECTS,
    SNAKEDENT_KNOB_EFFECTS,
    SNAKEDENT_MAX_STEP_S,
    WORMEYELET_EFFECTS,
    WORMEYELET_KNOB_EFFECTS,
    WORMEYELET_MAX_STEP_S,
)
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
    "jawcrimp": PlantSpec(PLANT_SPECS["jawcrimp"], {}, (), "jawcrimp", family="jawcrimp",
                          effects=JAWCRIMP_EFFECTS, knob_effects=JAWCRIMP_KNOB_EFFECTS,
                          max_step_s=JAWCRIMP_MAX_STEP_S),
    "cyclopebax": PlantSpec(PLANT_SPECS["cyclopebax"], {}, (), "cyclopebax",
                            family="cyclopebax", effects=CYCLOPEBAX_EFFECTS,
                            knob_effects=CYCLOPEBAX_KNOB_EFFECTS,
                            max_step_s=CYCLOPEBAX_MAX_STEP_S),
    "snakedent": PlantSpec(PLANT_SPECS["snakedent"], {}, (), "snakedent", family="snakedent",
                           effects=SNAKEDENT_EFFECTS, knob_effects=SNAKEDENT_KNOB_EFFECTS,
                           max_step_s=SNAKEDENT_MAX_STEP_S),
    "planetwist": PlantSpec(PLANT_SPECS["planetwist"], {}, (), "planetwist",
                            family="planetwist", effects=PLANETWIST_EFFECTS,
                            knob_effects=PLANETWIST_KNOB_EFFECTS,
                            max_step_s=PLANETWIST_MAX_STEP_S),
    "notchclutch": PlantSpec(PLANT_SPECS["notchclutch"], {}, (), "notchclutch",
                             family="notchclutch", effects=NOTCHCLUTCH_EFFECTS,
                             knob_effects=NOTCHCLUTCH_KNOB_EFFECTS,
                             max_step_s=NOTCHCLUTCH_MAX_STEP_S),
    "pronyring": PlantSpec(PLANT_SPECS["pronyring"], {}, (), "pronyring", family="pronyring",
                           effects=PRONYRING_EFFECTS, knob_effects=PRONYRING_KNOB_EFFECTS,
                           max_step_s=PRONYRING_MAX_STEP_S),
    "wormeyelet": PlantSpec(PLANT_SPECS["wormeyelet"], {}, (), "wormeyelet",
                            family="wormeyelet", effects=WORMEYELET_EFFECTS,
                            knob_effects=WORMEYELET_KNOB_EFFECTS,
                            max_step_s=WORMEYELET_MAX_STEP_S),
    "beltbraid": PlantSpec(PLANT_SPECS["beltbraid"], {}, (), "beltbraid", family="beltbraid",
                           effects=BELTBRAID_EFFECTS, knob_effects=BELTBRAID_KNOB_EFFECTS,
                           max_step_s=BELTBRAID_MAX_STEP_S),
    "rackgrease": PlantSpec(PLANT_SPECS["rackgrease"], {}, (), "rackgrease",
                            family="rackgrease", effects=RACKGREASE_EFFECTS,
                            knob_effects=RACKGREASE_KNOB_EFFECTS,
                            max_step_s=RACKGREASE_MAX_STEP_S),
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
