"""The blind plants whose physics has no time law (cyclopebax, session 21; snakedent, session
22) as the data of the cross-plant self-test: their presets."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from simrig.plants.cyclopebax import CycloPebaxPlant
from simrig.plants.cyclopebax.params import CycloPebaxKnob
from simrig.plants.snakedent import SnakeDentKnob, SnakeDentPlant
from tsmd.gap.presets import PRESETS, parse_plant_spec
from tsmd.gap.selftest import drive_plant, trajectory

BLIND = [("cyclopebax", CycloPebaxPlant, CycloPebaxKnob),
         ("snakedent", SnakeDentPlant, SnakeDentKnob)]
NAMES = [name for name, _plant, _knob in BLIND]


@pytest.mark.parametrize(("name", "plant_type", "_knob"), BLIND)
def test_preset_is_found_by_name_and_builds_a_family_unit(name: str, plant_type: type,
                                                          _knob: type) -> None:
    spec = parse_plant_spec(name)
    assert spec is PRESETS[name]
    plant = spec.build_unit(1, 0.1)
    assert isinstance(plant, plant_type)
    assert plant.knobs != spec.build_unit(2, 0.1).knobs  # the family's scatter, per unit


@pytest.mark.parametrize(("name", "_plant", "knob_type"), BLIND)
def test_case_factors_name_constants_of_the_plants_knobs(name: str, _plant: type,
                                                         knob_type: type) -> None:
    names = {f.name for f in dataclasses.fields(knob_type)}
    for factors in PRESETS[name].knob_effects.values():
        assert set(factors) <= names


@pytest.mark.parametrize("name", NAMES)
def test_cases_couple_the_planes_halve_the_rope_and_bend_the_sheath(name: str) -> None:
    preset = PRESETS[name]
    none = preset.build_unit(102, 0.1)
    coupled = preset.build_unit(102, 0.1, "coupling", **preset.case_effects("coupling"))
    soft = preset.build_unit(102, 0.1, "compliance", **preset.case_effects("compliance"))
    bent = preset.build_unit(102, 0.1, "curvature", **preset.case_effects("curvature"))
    for k in (0, 1):
        assert soft.knobs[k].tendon_stiffness_N == pytest.approx(
            0.5 * none.knobs[k].tendon_stiffness_N)
        assert bent.knobs[k] == none.knobs[k] == coupled.knobs[k]
    assert none.cross_takeup_share == 1.0
    assert coupled.cross_takeup_share > 1.0
    assert none.sheath_curvature_deg == 0.0
    assert bent.sheath_curvature_deg == pytest.approx(120.0)


@pytest.mark.parametrize("name", NAMES)
def test_rate_and_creep_are_not_run(name: str) -> None:
    preset = PRESETS[name]
    for case in ("rate", "creep"):
        assert not preset.supports(case)
    for case in ("none", "sensor", "coupling", "compliance", "curvature"):
        assert preset.supports(case)


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("case", ["coupling", "compliance", "curvature"])
def test_each_case_moves_the_tip_beyond_the_trackers_noise(name: str, case: str) -> None:
    preset = PRESETS[name]
    _t, q = trajectory(30.0, 50.0)
    off, _ = drive_plant(preset.build_unit(1, 0.1), q, 50.0, preset.max_step_s)
    on, _ = drive_plant(preset.build_unit(1, 0.1, case, **preset.case_effects(case)), q, 50.0,
                        preset.max_step_s)
    assert float(np.sqrt(np.mean((on - off) ** 2))) > 0.1
