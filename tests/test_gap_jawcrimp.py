"""The blind jawcrimp plant (session 20) as the data of the cross-plant self-test: its preset."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from simrig.plants.jawcrimp import JawCrimpKnob, JawCrimpPlant
from tsmd.gap.presets import PRESETS, parse_plant_spec
from tsmd.gap.selftest import drive_plant, trajectory


def test_jawcrimp_preset_is_found_by_name_and_builds_a_family_unit() -> None:
    spec = parse_plant_spec("jawcrimp")
    assert spec is PRESETS["jawcrimp"]
    plant = spec.build_unit(1, 0.1)
    assert isinstance(plant, JawCrimpPlant)
    assert plant.knobs != spec.build_unit(2, 0.1).knobs  # the family's scatter, per unit


def test_jawcrimp_case_factors_name_constants_of_the_plants_knobs() -> None:
    names = {f.name for f in dataclasses.fields(JawCrimpKnob)}
    for factors in PRESETS["jawcrimp"].knob_effects.values():
        assert set(factors) <= names


def test_jawcrimp_cases_halve_the_rope_speed_the_crimps_and_bend_the_sheath() -> None:
    jc = PRESETS["jawcrimp"]
    none = jc.build_unit(102, 0.1)
    soft = jc.build_unit(102, 0.1, "compliance", **jc.case_effects("compliance"))
    loose = jc.build_unit(102, 0.1, "creep", **jc.case_effects("creep"))
    bent = jc.build_unit(102, 0.1, "curvature", **jc.case_effects("curvature"))
    for k in (0, 1):
        assert soft.knobs[k].tendon_stiffness_N == pytest.approx(
            0.5 * none.knobs[k].tendon_stiffness_N)
        assert loose.knobs[k].crimp_creep_mm_per_s > 2.0 * none.knobs[k].crimp_creep_mm_per_s
        assert bent.knobs[k] == none.knobs[k]
    assert none.sheath_curvature_deg == 0.0
    assert bent.sheath_curvature_deg == pytest.approx(120.0)


def test_jawcrimp_coupling_and_rate_are_not_run() -> None:
    jc = PRESETS["jawcrimp"]
    for case in ("coupling", "rate"):
        assert not jc.supports(case)
    for case in ("none", "sensor", "compliance", "curvature", "creep"):
        assert jc.supports(case)


def test_jawcrimp_is_stepped_finer_than_a_20_ms_row() -> None:
    assert 0.0 < PRESETS["jawcrimp"].max_step_s < 0.02


@pytest.mark.parametrize("case", ["compliance", "curvature", "creep"])
def test_each_jawcrimp_case_moves_the_tip_beyond_the_trackers_noise(case: str) -> None:
    jc = PRESETS["jawcrimp"]
    _t, q = trajectory(30.0, 50.0)
    off, _ = drive_plant(jc.build_unit(1, 0.1), q, 50.0, jc.max_step_s)
    on, _ = drive_plant(jc.build_unit(1, 0.1, case, **jc.case_effects(case)), q, 50.0,
                        jc.max_step_s)
    assert float(np.sqrt(np.mean((on - off) ** 2))) > 0.1
