"""The blind archwave plant (session 19) as the data of the cross-plant self-test: its preset."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from simrig.plants.archwave import ArchWaveKnob, ArchWavePlant
from tsmd.gap.presets import PRESETS, parse_plant_spec
from tsmd.gap.selftest import drive_plant, trajectory


def test_archwave_preset_is_found_by_name_and_builds_a_family_unit() -> None:
    spec = parse_plant_spec("archwave")
    assert spec is PRESETS["archwave"]
    plant = spec.build_unit(1, 0.1)
    assert isinstance(plant, ArchWavePlant)
    assert plant.knobs != spec.build_unit(2, 0.1).knobs  # the family's scatter, per unit


def test_archwave_case_factors_name_constants_of_the_plants_knobs() -> None:
    names = {f.name for f in dataclasses.fields(ArchWaveKnob)}
    for factors in PRESETS["archwave"].knob_effects.values():
        assert set(factors) <= names


def test_archwave_compliance_doubles_rope_and_coil_and_coupling_rate_creep_are_not_run() -> None:
    aw = PRESETS["archwave"]
    none = aw.build_unit(102, 0.1)
    soft = aw.build_unit(102, 0.1, "compliance", **aw.case_effects("compliance"))
    bent = aw.build_unit(102, 0.1, "curvature", **aw.case_effects("curvature"))
    for k in (0, 1):
        assert soft.knobs[k].tendon_stiffness_N == pytest.approx(
            0.5 * none.knobs[k].tendon_stiffness_N)
        assert soft.knobs[k].coil_compliance_mm_per_N == pytest.approx(
            2.0 * none.knobs[k].coil_compliance_mm_per_N)
        assert bent.knobs[k] == none.knobs[k]
    assert none.sheath_curvature_deg == 0.0
    assert bent.sheath_curvature_deg == pytest.approx(120.0)
    for case in ("coupling", "rate", "creep"):
        assert not aw.supports(case)
    assert aw.supports("sensor") and aw.supports("none")


def test_archwave_is_stepped_finer_than_a_20_ms_row() -> None:
    assert 0.0 < PRESETS["archwave"].max_step_s < 0.02


@pytest.mark.parametrize("case", ["compliance", "curvature"])
def test_each_archwave_case_moves_the_tip_beyond_the_trackers_noise(case: str) -> None:
    aw = PRESETS["archwave"]
    _t, q = trajectory(30.0, 50.0)
    off, _ = drive_plant(aw.build_unit(1, 0.1), q, 50.0, aw.max_step_s)
    on, _ = drive_plant(aw.build_unit(1, 0.1, case, **aw.case_effects(case)), q, 50.0,
                        aw.max_step_s)
    assert float(np.sqrt(np.mean((on - off) ** 2))) > 0.1
