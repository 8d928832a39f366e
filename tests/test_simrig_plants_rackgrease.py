"""The rackgrease plant: a rack-and-pinion handle whose rack cocks in its guide, an eddy-current
knob damper, ropes over one capstan contact, a grease-packed section, a heavy head."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.plants import ramp_knobs

from simrig.analysis import measure_dead_zone_backlash
from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import Plant
from simrig.plants.rackgrease import NOMINAL_KNOBS, RackGreasePlant, make_rackgrease_plant
from simrig.plants.rackgrease.laws import (
    coulomb_ratio,
    eddy_torque_Nm,
    grease_moment,
    guide_friction_N,
    head_moment_Nmm,
    solve_rope,
)
from simrig.report import run_sweep

DT = 0.004


def hold(plant: RackGreasePlant, knobs: tuple[float, float], steps: int = 50
         ) -> tuple[np.ndarray, np.ndarray]:
    step = None
    for _ in range(steps):
        step = plant.step(DT, np.asarray(knobs, float))
    assert step is not None
    return step.tip_deg, step.knob_torque_Nm


def ramp(plant: RackGreasePlant, start: tuple[float, float], end: tuple[float, float],
         rate_deg_s: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """Move both knobs linearly from ``start`` to ``end``; the last tip and torque."""
    return ramp_knobs(plant, start, end, DT, rate_deg_s)


def sweep(plant: RackGreasePlant, knob: int = 0, other: float = 0.0):  # type: ignore[no-untyped-def]
    plant.reset()
    return run_sweep(plant, knob, dt_s=DT, other_deg=other)


def test_it_is_a_plant_and_the_factory_builds_the_nominal_unit() -> None:
    plant = make_rackgrease_plant()
    assert isinstance(plant, Plant)
    assert [p.k for p in plant.planes] == list(NOMINAL_KNOBS)


def test_rackgrease_is_registered_last_and_held_out() -> None:
    assert list(PLANT_SPECS)[-1] == "rackgrease"
    assert PLANT_ROLE["rackgrease"] == "held-out"
    assert isinstance(family_member("rackgrease", 101).build(), RackGreasePlant)
    assert set(SCATTER["rackgrease"]) <= set(family_member("rackgrease", 0).params["knobs"][0])


def test_knob_2_is_not_knob_1() -> None:
    assert NOMINAL_KNOBS[0] != NOMINAL_KNOBS[1]


def test_the_tip_does_not_move_inside_the_slack() -> None:
    plant = make_rackgrease_plant()
    rest, _ = hold(plant, (0.0, 0.0))
    tip, _ = ramp(plant, (0.0, 0.0), (10.0, 0.0))
    assert abs(tip[0] - rest[0]) < 0.2


def test_the_nominal_dead_zone_and_backlash_are_in_the_paper_s_range() -> None:
    rec = sweep(make_rackgrease_plant())
    m = measure_dead_zone_backlash(rec.knob_deg, rec.tip_deg)
    assert 10.0 <= m.dead_zone_pos_deg <= 25.0 and -25.0 <= m.dead_zone_neg_deg <= -10.0
    assert 8.0 <= m.backlash_pos_deg <= 25.0 and 8.0 <= m.backlash_neg_deg <= 25.0


def test_the_knob_torque_rises_once_the_rope_engages_and_falls_at_the_reversal() -> None:
    plant = make_rackgrease_plant()
    _, inside = ramp(plant, (0.0, 0.0), (10.0, 0.0))
    _, loaded = ramp(plant, (10.0, 0.0), (80.0, 0.0))
    _, reversed_ = ramp(plant, (80.0, 0.0), (74.0, 0.0))
    assert loaded[0] > 5.0 * abs(inside[0])
    assert reversed_[0] < 0.5 * loaded[0]


def test_hysteresis_grows_with_the_load_of_the_ropes() -> None:
    """The contact's capacity grows with the ropes' tension: after a reversal at a larger
    bend the knob travels further before the tip comes back by 1 deg."""
    def travel_to_move(amp: float) -> float:
        plant = make_rackgrease_plant()
        top, _ = ramp(plant, (0.0, 0.0), (amp, 0.0))
        for q in np.arange(amp, 0.0, -0.1):
            if plant.step(DT, np.array([q, 0.0])).tip_deg[0] < top[0] - 1.0:
                return amp - float(q)
        return math.inf

    assert travel_to_move(90.0) > 1.3 * travel_to_move(50.0)


def test_the_section_holds_a_residual_bend_once_the_ropes_are_slack() -> None:
    """The grease's yield moment holds the section off straight (no rope pulls it back; the
    rope's own lumen drag holds a little more)."""
    def released(section_yield_Nmm: float) -> float:
        k = dict(vars(NOMINAL_KNOBS[1]), section_yield_Nmm=section_yield_Nmm)
        plant = make_rackgrease_plant([NOMINAL_KNOBS[0], k])
        ramp(plant, (0.0, 0.0), (0.0, 80.0))
        return float(ramp(plant, (0.0, 80.0), (0.0, 0.0))[0][1])

    k = NOMINAL_KNOBS[1]
    held_deg = math.degrees(k.section_yield_Nmm / k.bend_stiffness_Nmm_per_rad)
    assert released(k.section_yield_Nmm) - released(0.0) == pytest.approx(held_deg, abs=1.0)


def test_gravity_sags_the_head_toward_negative_phi1_when_the_grease_lets_it() -> None:
    light = dict(vars(NOMINAL_KNOBS[0]), section_yield_Nmm=0.0, sheath_drag_N=0.0,
                 head_moment_Nmm=3.0)
    plant = make_rackgrease_plant([light, NOMINAL_KNOBS[1]])
    tip, _ = hold(plant, (0.0, 0.0), 200)
    assert tip[0] < -3.0


def test_the_planes_are_coupled() -> None:
    """The right-left bend adds wrap to the anterior-posterior ropes and shortens the head's
    lever: the same phi1 move loads its knob differently."""
    alone = make_rackgrease_plant()
    _, tau_alone = ramp(alone, (0.0, 0.0), (70.0, 0.0))
    both = make_rackgrease_plant()
    ramp(both, (0.0, 0.0), (0.0, 80.0))
    _, tau_both = ramp(both, (0.0, 80.0), (70.0, 80.0))
    assert tau_both[0] > 1.01 * tau_alone[0]


def test_the_eddy_damper_torque_grows_with_speed_then_peaks() -> None:
    assert eddy_torque_Nm(0.0, 0.02, 150.0) == 0.0
    assert eddy_torque_Nm(20.0, 0.02, 150.0) < eddy_torque_Nm(100.0, 0.02, 150.0)
    assert eddy_torque_Nm(150.0, 0.02, 150.0) == pytest.approx(0.02)
    assert eddy_torque_Nm(600.0, 0.02, 150.0) < 0.02
    assert eddy_torque_Nm(-20.0, 0.02, 150.0) == -eddy_torque_Nm(20.0, 0.02, 150.0)


def test_a_faster_knob_needs_more_torque_in_the_dead_zone() -> None:
    slow, fast = make_rackgrease_plant(), make_rackgrease_plant()
    _, tau_slow = ramp(slow, (0.0, 0.0), (10.0, 0.0), rate_deg_s=5.0)
    _, tau_fast = ramp(fast, (0.0, 0.0), (10.0, 0.0), rate_deg_s=60.0)
    assert tau_fast[0] > tau_slow[0] > 0.0


def test_the_cocked_rack_s_friction_is_proportional_to_the_pull() -> None:
    assert guide_friction_N(20.0, 0.35, 6.0, 18.0) == pytest.approx(
        2.0 * guide_friction_N(10.0, 0.35, 6.0, 18.0))
    assert guide_friction_N(10.0, 0.35, 6.0, 18.0) < guide_friction_N(10.0, 0.35, 9.0, 18.0)


def test_the_grease_is_a_gel_below_yield_and_flows_above() -> None:
    below = grease_moment(0.001, 0.0, 2000.0, 3.2, 750.0)
    assert below[0] == pytest.approx(2.0) and below[2] == 0.0
    above = grease_moment(0.1, 0.0, 2000.0, 3.2, 750.0)
    assert 3.2 < above[0] < 200.0 and above[2] > 0.0
    faster = grease_moment(0.1, 0.0, 2000.0, 3.2, 1500.0)
    assert faster[0] > above[0]  # plastic viscosity: a quicker bend meets more moment


def test_a_sliding_rope_obeys_the_capstan_law() -> None:
    c = coulomb_ratio(0.18, math.radians(350.0))
    tp, td, _, _, _ = solve_rope(0.0, 5.0, 0.0, 50.0, 40.0, 1e6, 0.0, c, 0.0)
    assert tp / td == pytest.approx(math.exp(0.18 * math.radians(350.0)), rel=1e-3)


def test_the_head_s_lever_shortens_with_either_plane_s_bend() -> None:
    straight = head_moment_Nmm(0.0, 0.0, 1.2)
    assert straight == pytest.approx(-1.2)
    assert abs(head_moment_Nmm(0.5, 0.0, 1.2)) < abs(straight)
    assert head_moment_Nmm(0.5, 0.8, 1.2) == pytest.approx(head_moment_Nmm(0.8, 0.5, 1.2))


def test_a_unit_is_the_same_catheter_every_time() -> None:
    a, b = family_member("rackgrease", 102).build(), family_member("rackgrease", 102).build()
    q = np.array([60.0, -40.0])
    assert np.array_equal(hold(a, tuple(q))[0], hold(b, tuple(q))[0])  # type: ignore[arg-type]


def test_scattered_units_bend_differently() -> None:
    tips = []
    for unit in (0, 1, 101):
        tips.append(ramp(family_member("rackgrease", unit).build(), (0.0, 0.0), (70.0, -70.0))[0])
    assert not np.allclose(tips[0], tips[1], atol=0.5)
    assert not np.allclose(tips[1], tips[2], atol=0.5)


def test_reset_returns_to_the_unloaded_state() -> None:
    plant = make_rackgrease_plant()
    first = ramp(plant, (0.0, 0.0), (60.0, 30.0))[0]
    plant.reset()
    assert np.allclose(ramp(plant, (0.0, 0.0), (60.0, 30.0))[0], first)


def test_more_slack_widens_the_dead_zone() -> None:
    plant, looser = make_rackgrease_plant(), make_rackgrease_plant()
    looser.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    tight_tip = ramp(plant, (0.0, 0.0), (40.0, 0.0))[0][0]
    assert ramp(looser, (0.0, 0.0), (40.0, 0.0))[0][0] < tight_tip - 3.0


def test_a_curved_sheath_loads_the_knob_more() -> None:
    plain, curved = make_rackgrease_plant(), make_rackgrease_plant(sheath_curvature_deg=90.0)
    assert ramp(curved, (0.0, 0.0), (70.0, 0.0))[1][0] > ramp(plain, (0.0, 0.0), (70.0, 0.0))[1][0]


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"knobs": [NOMINAL_KNOBS[0]]}, "2 knobs"),
    ({"knobs": [dict(vars(NOMINAL_KNOBS[0]), tendon_offset_mm=0.0), NOMINAL_KNOBS[1]]}, "> 0"),
    ({"knobs": [dict(vars(NOMINAL_KNOBS[0]), contact_fraction=1.0), NOMINAL_KNOBS[1]]},
     "contact_fraction"),
    ({"knobs": [dict(vars(NOMINAL_KNOBS[0]), slack_pos_mm=-1.0), NOMINAL_KNOBS[1]]}, ">= 0"),
])
def test_bad_constants_are_refused(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        make_rackgrease_plant(**kwargs)  # type: ignore[arg-type]


def test_unknown_constants_and_shape_changes_are_refused() -> None:
    with pytest.raises(TypeError, match="unknown"):
        make_rackgrease_plant([{"no_such": 1.0}, NOMINAL_KNOBS[1]])
    with pytest.raises(ValueError, match="reshape"):
        make_rackgrease_plant().reshape(twist_deg=3.0)


def test_bad_steps_are_refused() -> None:
    plant = make_rackgrease_plant()
    with pytest.raises(ValueError):
        plant.step(-DT, np.zeros(2))
    with pytest.raises(ValueError):
        plant.step(DT, np.array([math.nan, 0.0]))


def test_a_step_is_finite_for_a_zero_time_step_and_a_jump() -> None:
    plant = make_rackgrease_plant()
    assert np.all(np.isfinite(plant.step(0.0, np.array([30.0, -30.0])).tip_deg))
    out = plant.step(DT, np.array([-90.0, 90.0]))
    assert np.all(np.isfinite(out.tip_deg)) and np.all(np.isfinite(out.knob_torque_Nm))
