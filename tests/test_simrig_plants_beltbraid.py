"""The beltbraid plant: a belt-driven spring-return handle, ropes with distributed microslip in a
braided lumen, a braided shaft whose crossings slip, an asymmetrically notched section."""

from __future__ import annotations

import math

import numpy as np
import pytest
from support.plants import ramp_knobs

from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import Plant
from simrig.plants.beltbraid import NOMINAL_KNOBS, BeltBraidPlant, make_beltbraid_plant
from simrig.plants.beltbraid.laws import BraidRelays, microslip, microslip_rate
from tsmd.tracking_scenarios import PERIOD_S, scenarios

DT = 0.004


def ramp(plant: BeltBraidPlant, start: tuple[float, float], end: tuple[float, float],
         rate_deg_s: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """Move both knobs linearly from ``start`` to ``end``; the last tip and torque."""
    return ramp_knobs(plant, start, end, DT, rate_deg_s)


def loop(plant: BeltBraidPlant, knob: int, amp: float, other: float = 0.0,
         cycles: int = 2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Knob ``knob`` swept by a triangle +-amp (others at ``other``): knob, tip, torque."""
    plant.reset()
    q = np.zeros(2)
    q[1 - knob] = other
    path = np.concatenate([np.linspace(0, amp, 200), np.linspace(amp, -amp, 400),
                           np.linspace(-amp, 0, 200)] * cycles)
    ramp(plant, (0.0, 0.0), tuple(q))
    tips, taus = [], []
    for x in path:
        q[knob] = x
        s = plant.step(DT * 4, q)
        tips.append(s.tip_deg[knob])
        taus.append(s.knob_torque_Nm[knob])
    return path, np.array(tips), np.array(taus)


def test_it_is_a_plant_and_starts_straight() -> None:
    plant = make_beltbraid_plant()
    assert isinstance(plant, Plant)
    assert np.allclose(plant.step(DT, np.zeros(2)).tip_deg, 0.0)


def test_inside_the_slack_the_tip_stays_straight_and_the_knob_feels_only_the_handle() -> None:
    plant = make_beltbraid_plant()
    tip, torque = ramp(plant, (0.0, 0.0), (12.0, 0.0), rate_deg_s=10.0)
    assert abs(tip[0]) < 0.05
    assert np.all(plant.tensions_N == 0.0)
    p = NOMINAL_KNOBS[0]
    assert abs(torque[0]) < p.return_preload_Nm + p.return_rate_Nm_per_rad + p.handle_friction_Nm


def test_past_the_slack_the_tip_follows_at_the_paper_s_slope() -> None:
    plant = make_beltbraid_plant()
    tip40, _ = ramp(plant, (0.0, 0.0), (40.0, 0.0))
    tip80, _ = ramp(plant, (40.0, 0.0), (80.0, 0.0))
    assert 1.1 < (tip80[0] - tip40[0]) / 40.0 < 1.7


def test_after_a_reversal_the_tip_holds_while_the_knob_torque_falls() -> None:
    plant = make_beltbraid_plant()
    tip_top, tau_top = ramp(plant, (0.0, 0.0), (85.0, 0.0))
    tip_back, tau_back = ramp(plant, (85.0, 0.0), (80.0, 0.0))
    assert tip_top[0] - tip_back[0] < 2.0  # 5 deg back: the tip has hardly moved
    assert tau_back[0] < 0.6 * tau_top[0]  # the drum's load has fallen a lot


def test_the_release_branch_lies_above_the_loading_branch() -> None:
    q, tip, _ = loop(make_beltbraid_plant(), 0, 90.0)
    second = slice(len(q) // 2, None)
    qs, ts = q[second], tip[second]
    up = np.gradient(qs) > 0
    at = lambda sel: float(np.interp(50.0, qs[sel][np.argsort(qs[sel])],  # noqa: E731
                                     ts[sel][np.argsort(qs[sel])]))
    pos = qs > 0
    assert at(pos & ~up) - at(pos & up) > 8.0


def _loop_width(plant: BeltBraidPlant) -> float:
    q, tip, _ = loop(plant, 0, 90.0)
    second = slice(len(q) // 2, None)
    qs, ts = q[second], tip[second]
    up = np.gradient(qs) > 0
    sel_up, sel_dn = (qs > 0) & up, (qs > 0) & ~up
    lo = np.interp(55.0, np.sort(qs[sel_up]), ts[sel_up][np.argsort(qs[sel_up])])
    hi = np.interp(55.0, np.sort(qs[sel_dn]), ts[sel_dn][np.argsort(qs[sel_dn])])
    return float(hi - lo)


def test_more_wrap_in_the_anatomy_widens_the_hysteresis() -> None:
    straight = _loop_width(make_beltbraid_plant())
    curved = _loop_width(make_beltbraid_plant(sheath_curvature_deg=120.0))
    assert curved > straight + 3.0


def test_the_notches_make_the_section_stiffer_toward_the_negative_side() -> None:
    plant = make_beltbraid_plant()
    plant.knobs[0].p = NOMINAL_KNOBS[0]
    plant.knobs[0].slack_mm = [1.0, 1.0]
    pos, _ = ramp(plant, (0.0, 0.0), (70.0, 0.0))
    plant.reset()
    neg, _ = ramp(plant, (0.0, 0.0), (-70.0, 0.0))
    assert pos[0] > -neg[0] + 3.0


def test_a_loaded_other_plane_shortens_the_braid_and_delays_engagement() -> None:
    free = make_beltbraid_plant()
    ramp(free, (0.0, 0.0), (0.0, 0.0))
    tip_free, _ = ramp(free, (0.0, 0.0), (30.0, 0.0))
    loaded = make_beltbraid_plant()
    ramp(loaded, (0.0, 0.0), (0.0, 90.0))
    assert loaded.shortening_mm > 0.1
    tip_loaded, _ = ramp(loaded, (0.0, 90.0), (30.0, 90.0))
    assert tip_loaded[0] < tip_free[0] - 1.5


def _after_cycles_under_load(plant: BeltBraidPlant) -> float:
    ramp(plant, (0.0, 0.0), (70.0, 0.0))
    for _ in range(10):
        ramp(plant, (70.0, 0.0), (40.0, 0.0), 40.0)
        ramp(plant, (40.0, 0.0), (70.0, 0.0), 40.0)
    return float(plant.step(DT, np.array([70.0, 0.0])).tip_deg[0])


def test_the_belt_creeps_toward_unloading_while_it_carries_the_load() -> None:
    creeping = make_beltbraid_plant()
    tip = _after_cycles_under_load(creeping)
    assert creeping.knobs[0].creep_rad > 0.0
    no_creep = make_beltbraid_plant(knobs=[{"belt_creep_per_Nm": 0.0}, {}])
    assert tip < _after_cycles_under_load(no_creep) - 0.5
    assert no_creep.knobs[0].creep_rad == 0.0


def test_the_return_springs_push_the_knob_back_toward_centre() -> None:
    plant = make_beltbraid_plant()
    _, left = ramp(plant, (0.0, 0.0), (-8.0, 0.0), 2.0)
    _, right = ramp(plant, (-8.0, 0.0), (8.0, 0.0), 2.0)
    # moving slowly inside the slack: the seal's share is the same, the springs change side
    assert right[0] - left[0] > 1.5 * NOMINAL_KNOBS[0].return_preload_Nm


def test_microslip_loads_toward_full_slip_and_unloads_at_the_initial_rate() -> None:
    assert microslip(0.0, 10.0, 0.1) == pytest.approx(1.0, abs=1e-9)
    assert microslip(0.0, 0.01, 0.1) == pytest.approx(math.tanh(0.1))
    assert microslip(0.9, -0.05, 0.1) == pytest.approx(0.4)
    assert microslip_rate(0.5, 1.0, 0.1) == pytest.approx(7.5)
    assert microslip_rate(0.5, -1.0, 0.1) == pytest.approx(10.0)


def test_braid_crossings_hold_their_slip_until_the_load_falls_well_below() -> None:
    braid = BraidRelays(onset_N=4.0, span_N=40.0, hold_N=10.0, slip_mm=0.3)
    assert braid.update(2.0) == 0.0
    up = braid.update(30.0)
    assert 0.0 < up < 0.3
    assert braid.update(28.0) == up  # a small fall moves no crossing back
    assert braid.update(5.0) < up
    assert braid.update(100.0) == pytest.approx(0.3)


def test_more_slack_widens_the_dead_zone() -> None:
    plant = make_beltbraid_plant()
    before, _ = ramp(plant, (0.0, 0.0), (35.0, 0.0))
    plant.reset()
    plant.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    after, _ = ramp(plant, (0.0, 0.0), (35.0, 0.0))
    assert after[0] < before[0] - 3.0


def test_a_unit_is_deterministic_and_units_differ() -> None:
    q = np.array([60.0, -40.0])
    a = [family_member("beltbraid", 103).build() for _ in range(2)]
    b = family_member("beltbraid", 104).build()
    tips = []
    for plant in (*a, b):
        tip, _ = ramp(plant, (0.0, 0.0), tuple(q))  # type: ignore[arg-type]
        tips.append(tip)
    assert np.array_equal(tips[0], tips[1])
    assert not np.allclose(tips[0], tips[2], atol=0.2)


def test_beltbraid_is_registered_and_held_out() -> None:
    assert "beltbraid" in PLANT_SPECS
    assert PLANT_ROLE["beltbraid"] == "held-out"
    assert isinstance(family_member("beltbraid", 101).build(), BeltBraidPlant)
    assert set(SCATTER["beltbraid"]) <= set(family_member("beltbraid", 0).params["knobs"][0])


def test_knob_2_is_not_knob_1() -> None:
    assert NOMINAL_KNOBS[0] != NOMINAL_KNOBS[1]


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"knobs": [{"belt": 1.0}, {}]}, "unknown beltbraid knob constants: belt"),
        ({"knobs": [{}]}, "beltbraid takes 2 knobs"),
        ({"knobs": ["x", {}]}, "must be a dict"),
    ],
)
def test_bad_constants_are_refused(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        make_beltbraid_plant(**kwargs)  # type: ignore[arg-type]


def test_bad_step_input_is_refused() -> None:
    with pytest.raises(ValueError):
        make_beltbraid_plant().step(-1.0, np.zeros(2))
    with pytest.raises(ValueError):
        make_beltbraid_plant().step(DT, np.array([math.nan, 0.0]))


def test_the_tracking_protocol_with_its_jumps_between_scenarios_stays_bounded() -> None:
    """The protocol's scenarios start where the last ended: a 60 deg jump in one step once left
    the linearised friction past its capacity and the flags cycling, and the bend diverged."""
    plant = family_member("beltbraid", 101).build()
    for s in scenarios(quick=True):
        for row in s.q_deg:
            tip = plant.step(PERIOD_S, row).tip_deg
            assert np.all(np.abs(tip) < 120.0)
