"""The blind plants as the data of the cross-plant self-test: their presets (cyclopebax, session
21; snakedent, session 22; planetwist, session 23, none with a time law at the tip; notchclutch,
session 24, whose braid stiffens with strain rate and whose liner soaks; pronyring, session 25,
whose Pebax section relaxes with a Prony spectrum; wormeyelet, session 26, whose eyelets take
wrap from the other plane's bend; beltbraid, session 27, whose braided shaft's crossings slip
under all four ropes' load; rackgrease, session 28, whose ropes wrap a share of the section's
total bend and whose grease flows with a plastic viscosity)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from simrig.plants.beltbraid import BeltBraidPlant
from simrig.plants.beltbraid import KnobParams as BeltBraidKnob
from simrig.plants.cyclopebax import CycloPebaxPlant
from simrig.plants.cyclopebax.params import CycloPebaxKnob
from simrig.plants.notchclutch.params import NotchClutchKnob
from simrig.plants.notchclutch.plant import NotchClutchPlant
from simrig.plants.planetwist import PlanetTwistKnob, PlanetTwistPlant
from simrig.plants.pronyring.params import KnobConstants as PronyRingKnob
from simrig.plants.pronyring.plant import PronyRingPlant
from simrig.plants.rackgrease import KnobConstants as RackGreaseKnob
from simrig.plants.rackgrease import RackGreasePlant
from simrig.plants.snakedent import SnakeDentKnob, SnakeDentPlant
from simrig.plants.wormeyelet import WormEyeletKnob, WormEyeletPlant
from tsmd.gap.presets import PRESETS, parse_plant_spec
from tsmd.gap.selftest import drive_plant, trajectory

BLIND = [("cyclopebax", CycloPebaxPlant, CycloPebaxKnob),
         ("snakedent", SnakeDentPlant, SnakeDentKnob),
         ("planetwist", PlanetTwistPlant, PlanetTwistKnob),
         ("notchclutch", NotchClutchPlant, NotchClutchKnob),
         ("pronyring", PronyRingPlant, PronyRingKnob),
         ("wormeyelet", WormEyeletPlant, WormEyeletKnob),
         ("beltbraid", BeltBraidPlant, BeltBraidKnob),
         ("rackgrease", RackGreasePlant, RackGreaseKnob)]
NAMES = [name for name, _plant, _knob in BLIND]
TIMELESS = ["cyclopebax", "snakedent", "planetwist", "wormeyelet", "beltbraid"]
"""The blind plants with no law of speed or time at the tip."""


def _knobs(plant: Any) -> list[Any]:
    """A plant's per-knob constants (beltbraid keeps them apart from its knobs' state,
    rackgrease in its planes)."""
    if isinstance(plant, BeltBraidPlant):
        return list(plant.params)
    if isinstance(plant, RackGreasePlant):
        return [plane.k for plane in plant.planes]
    return list(plant.knobs)


def _share_keyword(plant: Any) -> list[float]:
    return [plant.cross_takeup_share] * 2


def _takeup_keyword(plant: Any) -> list[float]:
    return [plant.coupling] * 2


def _takeup_constant(plant: Any) -> list[float]:
    return [knob.cross_takeup for knob in plant.knobs]


def _cross_wrap_constant(plant: Any) -> list[float]:
    return [knob.cross_wrap for knob in plant.knobs]


def _braid_constant(plant: Any) -> list[float]:
    return [knob.braid_slip_mm for knob in plant.params]


def _section_wrap_constant(plant: Any) -> list[float]:
    return [plane.k.section_wrap_fraction for plane in plant.planes]


TAKEUP: dict[str, tuple[Callable[[Any], list[float]], set[str]]] = {
    "cyclopebax": (_share_keyword, set()),
    "snakedent": (_share_keyword, set()),
    "planetwist": (_takeup_constant, {"cross_takeup"}),
    "notchclutch": (_takeup_keyword, set()),
    "pronyring": (_takeup_keyword, set()),
    "wormeyelet": (_cross_wrap_constant, {"cross_wrap"}),
    "beltbraid": (_braid_constant, {"braid_slip_mm"}),
    "rackgrease": (_section_wrap_constant, {"section_wrap_fraction"}),
}
"""How strongly the other plane's bend takes up a plane's ropes (on wormeyelet: adds wrap at
its eyelets; on beltbraid: how far the braid's crossings slip under the ropes' load; on
rackgrease: the share of the section's total bend its ropes wrap), per plant,
and which knob constants the coupling case may change (a keyword on cyclopebax and snakedent,
planetwist's, wormeyelet's and beltbraid's own knob constant)."""


@pytest.mark.parametrize(("name", "plant_type", "_knob"), BLIND)
def test_preset_is_found_by_name_and_builds_a_family_unit(name: str, plant_type: type,
                                                          _knob: type) -> None:
    spec = parse_plant_spec(name)
    assert spec is PRESETS[name]
    plant = spec.build_unit(1, 0.1)
    assert isinstance(plant, plant_type)
    assert _knobs(plant) != _knobs(spec.build_unit(2, 0.1))  # the family's scatter, per unit


@pytest.mark.parametrize(("name", "_plant", "knob_type"), BLIND)
def test_case_factors_name_constants_of_the_plants_knobs(name: str, _plant: type,
                                                         knob_type: type) -> None:
    names = {f.name for f in dataclasses.fields(knob_type)}
    for factors in PRESETS[name].knob_effects.values():
        assert set(factors) <= names


@pytest.mark.parametrize("name", NAMES)
def test_cases_halve_the_rope_and_bend_the_sheath(name: str) -> None:
    preset = PRESETS[name]
    none = preset.build_unit(102, 0.1)
    soft = preset.build_unit(102, 0.1, "compliance", **preset.case_effects("compliance"))
    bent = preset.build_unit(102, 0.1, "curvature", **preset.case_effects("curvature"))
    for k in (0, 1):
        assert _knobs(soft)[k].tendon_stiffness_N == pytest.approx(
            0.5 * _knobs(none)[k].tendon_stiffness_N)
        assert _knobs(bent)[k] == _knobs(none)[k]
    assert none.sheath_curvature_deg == 0.0
    assert bent.sheath_curvature_deg == pytest.approx(120.0)


@pytest.mark.parametrize("name", NAMES)
def test_coupling_case_only_raises_the_other_planes_takeup(name: str) -> None:
    preset = PRESETS[name]
    takeup, constants = TAKEUP[name]
    none = preset.build_unit(102, 0.1)
    coupled = preset.build_unit(102, 0.1, "coupling", **preset.case_effects("coupling"))
    for k in (0, 1):
        assert takeup(coupled)[k] > 1.5 * takeup(none)[k]
        kept = {c: getattr(_knobs(none)[k], c) for c in constants}
        assert dataclasses.replace(_knobs(coupled)[k], **kept) == _knobs(none)[k]
    assert coupled.sheath_curvature_deg == none.sheath_curvature_deg


@pytest.mark.parametrize("name", TIMELESS)
def test_rate_and_creep_are_not_run(name: str) -> None:
    preset = PRESETS[name]
    for case in ("rate", "creep"):
        assert not preset.supports(case)
    for case in ("none", "sensor", "coupling", "compliance", "curvature"):
        assert preset.supports(case)


TIME_LAWS = {"notchclutch": (("rate", "rate_stiffening", 4.0), ("creep", "soak_time_s", 4.0)),
             "pronyring": (("rate", "prony_fast_Nmm_per_rad", 2.0),
                           ("creep", "prony_slow_Nmm_per_rad", 1.5))}
"""The blind plants with a law of speed or time at the tip: per case the one knob constant it
scales, and the least factor."""


@pytest.mark.parametrize("name", sorted(TIME_LAWS))
def test_rate_and_creep_each_scale_one_law_of_speed_or_time(name: str) -> None:
    preset = PRESETS[name]
    none = preset.build_unit(102, 0.1)
    for case, constant, least in TIME_LAWS[name]:
        assert preset.supports(case)
        changed = preset.build_unit(102, 0.1, case, **preset.case_effects(case))
        for k in (0, 1):
            assert getattr(changed.knobs[k], constant) > least * getattr(none.knobs[k], constant)
            kept = {constant: getattr(none.knobs[k], constant)}
            assert dataclasses.replace(changed.knobs[k], **kept) == none.knobs[k]
        assert changed.coupling == none.coupling == 0.0


@pytest.mark.parametrize(("name", "case"),
                         [(n, c) for n in NAMES for c in ("coupling", "compliance", "curvature")]
                         + [(n, c) for n in sorted(TIME_LAWS) for c in ("rate", "creep")]
                         + [("rackgrease", "rate")])
def test_each_case_moves_the_tip_beyond_the_trackers_noise(name: str, case: str) -> None:
    preset = PRESETS[name]
    _t, q = trajectory(30.0, 50.0)
    off, _ = drive_plant(preset.build_unit(1, 0.1), q, 50.0, preset.max_step_s)
    on, _ = drive_plant(preset.build_unit(1, 0.1, case, **preset.case_effects(case)), q, 50.0,
                        preset.max_step_s)
    assert float(np.sqrt(np.mean((on - off) ** 2))) > 0.1


RACKGREASE_VISCOSITIES = ("grease_viscosity_N_s_per_mm", "section_viscosity_Nmm_s_per_rad")
"""The grease's plastic viscosity, as the film on the ropes and as the section's packing."""


def test_rackgrease_rate_makes_the_one_grease_more_viscous_and_creep_is_not_run() -> None:
    preset = PRESETS["rackgrease"]
    assert preset.supports("rate")
    assert not preset.supports("creep")
    none = preset.build_unit(102, 0.1)
    thick = preset.build_unit(102, 0.1, "rate", **preset.case_effects("rate"))
    for k in (0, 1):
        before, after = _knobs(none)[k], _knobs(thick)[k]
        for constant in RACKGREASE_VISCOSITIES:
            assert getattr(after, constant) > 1.5 * getattr(before, constant)
        kept = {c: getattr(before, c) for c in RACKGREASE_VISCOSITIES}
        assert dataclasses.replace(after, **kept) == before
    assert thick.sheath_curvature_deg == none.sheath_curvature_deg == 0.0


def test_rackgrease_tip_does_not_move_while_the_knobs_hold_after_the_grease_settles() -> None:
    """Why creep is not run: past the grease's flow (well inside a second) nothing reads time."""
    preset = PRESETS["rackgrease"]
    ramp = np.linspace(0.0, 1.0, 100)[:, None] * np.array([75.0, 30.0])
    held = np.vstack([ramp, np.tile(np.array([75.0, 30.0]), (1000, 1))])
    tip, _current = drive_plant(preset.build_unit(1, 0.1), held, 50.0, preset.max_step_s)
    assert np.max(np.abs(tip[150:] - tip[150])) < 1e-3
