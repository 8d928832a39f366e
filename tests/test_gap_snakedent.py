"""The blind snakedent plant (session 22) as the data of the cross-plant self-test: its preset."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from simrig.plants.snakedent import SnakeDentKnob, SnakeDentPlant
from tsmd.gap.presets import PRESETS, parse_plant_spec
from tsmd.gap.selftest import drive_plant, trajectory


def test_snakedent_preset_is_found_by_name_and_builds_a_family_unit() -> None:
    spec = parse_plant_spec("snakedent")
    assert spec is PRESETS["snakedent"]
    plant = spec.build_unit(1, 0.1)
    assert isinstance(plant, SnakeDentPlant)
    assert plant.knobs != spec.build_unit(2, 0.1).knobs  # the family's scatter, per unit


def test_snakedent_case_factors_name_constants_of_the_plants_knobs() -> None:
    names = {f.name for f in dataclasses.fields(SnakeDentKnob)}
    for factors in PRESETS["snakedent"].knob_effects.values():
        assert set(factors) <= names


def test_snakedent_cases_couple_the_planes_halve_the_rope_and_bend_the_sheath() -> None:
    sd = PRESETS["snakedent"]
    none = sd.build_unit(102, 0.1)
    coupled = sd.build_unit(102, 0.1, "coupling", **sd.case_effects("coupling"))
    soft = sd.build_unit(102, 0.1, "compliance", **sd.case_effects("compliance"))
    bent = sd.build_unit(102, 0.1, "curvature", **sd.case_effects("curvature"))
    for k in (0, 1):
        assert soft.knobs[k].tendon_stiffness_N == pytest.approx(
            0.5 * none.knobs[k].tendon_stiffness_N)
        assert bent.knobs[k] == none.knobs[k] == coupled.knobs[k]
    assert none.cross_takeup_share == 1.0
    assert coupled.cross_takeup_share > 1.0
    assert none.sheath_curvature_deg == 0.0
    assert bent.sheath_curvature_deg == pytest.approx(120.0)


def test_snakedent_rate_and_creep_are_not_run() -> None:
    sd = PRESETS["snakedent"]
    for case in ("rate", "creep"):
        assert not sd.supports(case)
    for case in ("none", "sensor", "coupling", "compliance", "curvature"):
        assert sd.supports(case)


@pytest.mark.parametrize("case", ["coupling", "compliance", "curvature"])
def test_each_snakedent_case_moves_the_tip_beyond_the_trackers_noise(case: str) -> None:
    sd = PRESETS["snakedent"]
    _t, q = trajectory(30.0, 50.0)
    off, _ = drive_plant(sd.build_unit(1, 0.1), q, 50.0, sd.max_step_s)
    on, _ = drive_plant(sd.build_unit(1, 0.1, case, **sd.case_effects(case)), q, 50.0,
                        sd.max_step_s)
    assert float(np.sqrt(np.mean((on - off) ** 2))) > 0.1
