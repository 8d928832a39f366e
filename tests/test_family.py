"""Units of the product: scatter reproducible by seed, different across units, named variants."""

from __future__ import annotations

import numpy as np
import pytest

from simrig.family import (
    DEVELOPMENT_UNITS,
    HELD_OUT_UNITS,
    PLANT_SPECS,
    SCATTER,
    VARIANTS,
    family,
    family_member,
)
from simrig.plant import Plant, PlantLoadError, as_plant_step, load_plant
from simrig.rig import DEFAULT_CURRENT_SENSOR


@pytest.mark.parametrize("plant", sorted(PLANT_SPECS))
def test_a_unit_is_the_same_catheter_every_time_it_is_drawn(plant: str) -> None:
    assert family_member(plant, 3).params == family_member(plant, 3).params


@pytest.mark.parametrize("plant", sorted(PLANT_SPECS))
def test_units_and_seeds_draw_different_catheters(plant: str) -> None:
    a = family_member(plant, 3).params["knobs"][0]
    assert a != family_member(plant, 4).params["knobs"][0]
    assert a != family_member(plant, 3, seed=1).params["knobs"][0]


@pytest.mark.parametrize("plant", sorted(PLANT_SPECS))
def test_every_scattered_constant_stays_within_its_documented_range(plant: str) -> None:
    nominal = family_member(plant, 0).params["knobs"]
    moved = set()
    for unit in DEVELOPMENT_UNITS + HELD_OUT_UNITS:
        for k, knob in enumerate(family_member(plant, unit).params["knobs"]):
            for name, half in SCATTER[plant].items():
                base = nominal[k][name]
                assert abs(knob[name] - base) <= half * abs(base) + 1e-12
                if knob[name] != base:
                    moved.add(name)
    assert moved == {n for n in SCATTER[plant] if nominal[0][n] != 0.0}


@pytest.mark.parametrize("plant", sorted(PLANT_SPECS))
def test_unit_zero_is_the_nominal_plant(plant: str) -> None:
    member = family_member(plant, 0)
    assert member.unit_set == "nominal"
    a, b = member.build(), load_plant(PLANT_SPECS[plant])
    for q in np.linspace(0.0, 80.0, 200):
        sa, sb = a.step(0.004, np.array([q, -q])), b.step(0.004, np.array([q, -q]))
    assert np.allclose(sa.tip_deg, sb.tip_deg)


def test_development_and_held_out_units_do_not_overlap() -> None:
    assert not set(DEVELOPMENT_UNITS) & set(HELD_OUT_UNITS)
    assert family_member("lumped", HELD_OUT_UNITS[0]).unit_set == "held-out"
    assert family_member("lumped", DEVELOPMENT_UNITS[0]).unit_set == "development"


@pytest.mark.parametrize("plant", sorted(PLANT_SPECS))
@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_every_variant_builds_a_plant(plant: str, variant: str) -> None:
    assert isinstance(family_member(plant, 0, variant).build(), Plant)


def test_worn_variant_has_more_friction_than_its_unit() -> None:
    plain = family_member("lumped", 2).params["knobs"][0]
    worn = family_member("lumped", 2, "worn").params["knobs"][0]
    assert worn["sheath_friction"] == pytest.approx(1.3 * plain["sheath_friction"])


def test_drive_variants_change_the_rig_not_the_plant() -> None:
    noisy = family_member("capstan", 0, "noisy-sensor")
    assert noisy.params == family_member("capstan", 0).params
    assert noisy.current_sensor["noise_A"] > DEFAULT_CURRENT_SENSOR["noise_A"]
    rough = family_member("capstan", 0, "motor-friction")
    assert rough.rig_kwargs()["motor"].friction_Nm > family_member("capstan", 0).motor.friction_Nm


def test_family_lists_nominal_units_then_variants() -> None:
    members = family("lumped", 2, held_out=True, variants=True)
    assert [m.unit for m in members[:3]] == [0, *HELD_OUT_UNITS[:2]]
    assert [m.variant for m in members[3:]] == list(VARIANTS)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"plant": "rubber"}, "unknown plant 'rubber'"),
        ({"plant": "lumped", "unit": -1}, "unit must be an integer >= 0"),
        ({"plant": "lumped", "variant": "gold"}, "unknown variant 'gold'"),
    ],
)
def test_bad_member_requests_are_refused(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        family_member(**kwargs)  # type: ignore[arg-type]


def test_a_family_member_can_be_built_through_the_plant_loader() -> None:
    direct = family_member("lumped", 101).build()
    loaded = load_plant("simrig.family:make_family_plant", {"plant": "lumped", "unit": 101})
    knob = np.array([30.0, -20.0])
    for _ in range(50):
        a = as_plant_step(direct.step(0.004, knob))
        b = as_plant_step(loaded.step(0.004, knob))
    assert np.array_equal(a.tip_deg, b.tip_deg)
    assert np.array_equal(a.knob_torque_Nm, b.knob_torque_Nm)
