"""The blind warmgear plant (session 18) as the data of the cross-plant self-test: its preset."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from simrig.plants.warmgear import WarmGearKnobParams, WarmGearPlant
from tsmd.gap.presets import PRESETS, parse_plant_spec
from tsmd.gap.selftest import drive_plant, trajectory


def test_warmgear_preset_is_found_by_name_and_builds_a_family_unit() -> None:
    spec = parse_plant_spec("warmgear")
    assert spec is PRESETS["warmgear"]
    plant = spec.build_unit(1, 0.1)
    assert isinstance(plant, WarmGearPlant)
    assert plant.knobs != spec.build_unit(2, 0.1).knobs  # the family's scatter, per unit


def test_warmgear_case_factors_name_constants_of_the_plants_knobs() -> None:
    names = {f.name for f in dataclasses.fields(WarmGearKnobParams)}
    for factors in PRESETS["warmgear"].knob_effects.values():
        assert set(factors) <= names


def test_warmgear_cases_scale_the_units_film_and_rope_and_coupling_creep_are_not_run() -> None:
    wg = PRESETS["warmgear"]
    none = wg.build_unit(102, 0.1)
    rate = wg.build_unit(102, 0.1, "rate", **wg.case_effects("rate"))
    soft = wg.build_unit(102, 0.1, "compliance", **wg.case_effects("compliance"))
    bent = wg.build_unit(102, 0.1, "curvature", **wg.case_effects("curvature"))
    for k in (0, 1):
        assert rate.knobs[k].film_viscous_N_s_per_mm == pytest.approx(
            2.0 * none.knobs[k].film_viscous_N_s_per_mm)
        assert soft.knobs[k].tendon_stiffness_N == pytest.approx(
            0.5 * none.knobs[k].tendon_stiffness_N)
        assert rate.knobs[k].tendon_stiffness_N == none.knobs[k].tendon_stiffness_N
    assert none.sheath_curvature_deg == 0.0
    assert bent.sheath_curvature_deg == pytest.approx(60.0)
    assert not wg.supports("coupling")
    assert not wg.supports("creep")
    assert wg.supports("sensor") and wg.supports("none")


def test_warmgear_is_stepped_finer_than_a_20_ms_row() -> None:
    assert 0.0 < PRESETS["warmgear"].max_step_s < 0.02


@pytest.mark.parametrize("case", ["rate", "compliance", "curvature"])
def test_each_warmgear_case_moves_the_tip_beyond_the_trackers_noise(case: str) -> None:
    wg = PRESETS["warmgear"]
    _t, q = trajectory(30.0, 50.0)
    off, _ = drive_plant(wg.build_unit(1, 0.1), q, 50.0, wg.max_step_s)
    on, _ = drive_plant(wg.build_unit(1, 0.1, case, **wg.case_effects(case)), q, 50.0,
                        wg.max_step_s)
    assert float(np.sqrt(np.mean((on - off) ** 2))) > 0.1
