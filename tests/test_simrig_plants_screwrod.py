"""The screwrod plant: lead-screw handle, creeping UHMWPE tendons, rod tip against a wall."""

from __future__ import annotations

import math

import numpy as np
import pytest

from simrig.plant import PlantLoadError, load_plant
from simrig.plants.screwrod import ScrewRodPlant, make_screwrod_plant

SPEC = "simrig.plants.screwrod:make_screwrod_plant"


def _ramp(plant: ScrewRodPlant, knob: int, to_deg: float, dt_s: float = 0.004,
          rate_deg_s: float = 20.0, other_deg: float = 0.0,
          start_deg: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    n = max(1, int(abs(to_deg - start_deg) / rate_deg_s / dt_s))
    tips, torques = [], []
    for q in np.linspace(start_deg, to_deg, n + 1)[1:]:
        cmd = np.array([q, other_deg]) if knob == 0 else np.array([other_deg, q])
        s = plant.step(dt_s, cmd)
        tips.append(s.tip_deg[knob])
        torques.append(s.knob_torque_Nm[knob])
    return np.array(tips), np.array(torques)


def test_the_tip_does_not_depend_on_the_time_step() -> None:
    fine, coarse = make_screwrod_plant(), make_screwrod_plant()
    a, _ = _ramp(fine, 1, 80.0, dt_s=0.0001, rate_deg_s=40.0)
    b, _ = _ramp(coarse, 1, 80.0, dt_s=0.004, rate_deg_s=40.0)
    assert abs(a[-1] - b[-1]) < 0.2
    assert abs(a[-1]) > 40.0


def test_two_plants_driven_alike_answer_alike() -> None:
    a, b = make_screwrod_plant(), make_screwrod_plant()
    ta, qa = _ramp(a, 0, 70.0)
    tb, qb = _ramp(b, 0, 70.0)
    assert np.array_equal(ta, tb) and np.array_equal(qa, qb)


def test_the_wall_free_plane_bends_alike_both_ways() -> None:
    pos, neg = make_screwrod_plant(), make_screwrod_plant()
    tp, qp = _ramp(pos, 1, 85.0)
    tn, qn = _ramp(neg, 1, -85.0)
    assert tp[-1] == pytest.approx(-tn[-1], abs=1e-6)
    assert qp[-1] == pytest.approx(-qn[-1], abs=1e-9)


def test_the_wall_holds_the_anterior_bend_back() -> None:
    walled, free = make_screwrod_plant(), make_screwrod_plant(wall_stiffness_N_per_mm=0.0)
    tw, _ = _ramp(walled, 0, 90.0)
    tf, _ = _ramp(free, 0, 90.0)
    back, _ = _ramp(make_screwrod_plant(), 0, -90.0)
    assert tw[-1] < tf[-1] - 1.0
    assert tf[-1] == pytest.approx(-back[-1], abs=1e-6)


def test_reset_returns_to_straight_and_unloaded() -> None:
    plant = make_screwrod_plant()
    _ramp(plant, 0, 80.0, other_deg=40.0)
    plant.reset()
    s = plant.step(0.004, np.array([0.0, 0.0]))
    assert np.all(s.tip_deg == 0.0)
    assert np.all(np.abs(s.knob_torque_Nm) <= plant.knobs[0].p.handle_friction_Nm + 1e-12)
    assert np.all(plant.creep_mm == 0.0)


def test_the_tip_stays_still_in_the_dead_zone() -> None:
    tips, torques = _ramp(make_screwrod_plant(), 0, 15.0)
    assert np.max(np.abs(tips)) < 0.5
    assert np.max(np.abs(torques)) < 0.02


def test_the_self_locking_collar_turns_the_torque_round_at_a_reversal() -> None:
    plant = make_screwrod_plant()
    _, up = _ramp(plant, 0, 80.0)
    _, down = _ramp(plant, 0, 77.0, start_deg=80.0)
    assert up[-1] > 0.05
    assert down[-1] < 0.0  # back-driving efficiency below zero: the motor pulls the load back


def test_loaded_tendons_creep_over_cycles() -> None:
    plant = make_screwrod_plant()
    _ramp(plant, 0, 90.0, rate_deg_s=45.0)
    first = plant.creep_mm[0, 0]
    for _ in range(2):
        _ramp(plant, 0, 0.0, rate_deg_s=45.0, start_deg=90.0)
        _ramp(plant, 0, 90.0, rate_deg_s=45.0)
    assert 0.0 < first < plant.creep_mm[0, 0] < plant.knobs[0].p.creep_limit_mm


def test_more_slack_widens_the_dead_zone() -> None:
    plain, slack = make_screwrod_plant(), make_screwrod_plant()
    slack.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    tp, _ = _ramp(plain, 0, 50.0)
    ts, _ = _ramp(slack, 0, 50.0)
    assert ts[-1] < tp[-1] - 3.0


def test_a_bent_other_plane_adds_friction_to_this_one() -> None:
    straight, bent = make_screwrod_plant(), make_screwrod_plant()
    _ramp(bent, 1, 70.0)
    ts, qs = _ramp(straight, 0, 80.0)
    tb, qb = _ramp(bent, 0, 80.0, other_deg=70.0)
    assert qb[-1] > qs[-1]
    assert tb[-1] < ts[-1]


@pytest.mark.parametrize(("dt_s", "knob"), [(-0.001, [0.0, 0.0]), (0.001, [math.nan, 0.0]),
                                            (0.001, [1.0]), (0.001, "ab")])
def test_bad_step_input_is_refused(dt_s: float, knob: object) -> None:
    with pytest.raises(ValueError, match="dt_s|knob_deg"):
        make_screwrod_plant().step(dt_s, knob)  # type: ignore[arg-type]


@pytest.mark.parametrize(("params", "message"), [
    ({"knobs": [{"slack_pos_mm": -1.0}, {}]}, "slack_pos_mm must be finite"),
    ({"knobs": [{"gold": 1.0}, {}]}, "unknown knob constant"),
    ({"knobs": [{}]}, "knobs must be a list of 2"),
    ({"wall_gap_mm": 0.0}, "wall_gap_mm"),
    ({"knobs": [{"screw_lead_mm": 200.0}, {}]}, "lead angle"),
])
def test_bad_constants_are_refused_in_one_line(params: dict[str, object], message: str) -> None:
    with pytest.raises(PlantLoadError, match=message) as err:
        load_plant(SPEC, params)
    assert "\n" not in str(err.value)


def test_an_unknown_shape_change_is_refused() -> None:
    with pytest.raises(PlantLoadError, match="cannot reshape"):
        make_screwrod_plant().reshape(twist_deg=3.0)


def test_closed_links_stop_the_tip_near_its_bend_limit() -> None:
    plant = make_screwrod_plant()
    tips, torques = _ramp(plant, 1, 180.0, rate_deg_s=60.0)
    limit = plant.knobs[1].p.bend_limit_deg
    assert limit < tips[-1] < limit + 8.0
    assert torques[-1] > 3.0 * torques[len(torques) // 2]
