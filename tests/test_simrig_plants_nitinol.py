"""The nitinol plant (blind, session 14): its physics' behaviours, stability and refusals."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from simrig.plant import PlantLoadError, load_plant
from simrig.plants.nitinol import NitinolPlant, make_nitinol_plant

SPEC = "simrig.plants.nitinol:make_nitinol_plant"


def _ramp(plant: NitinolPlant, knob: int, to_deg: float, rate_deg_s: float = 20.0,
          dt_s: float = 0.004, other_deg: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Move ``knob`` from where it is to ``to_deg``; tips and torques of that knob."""
    start = math.degrees(plant.knobs[knob].knob_rad)
    n = max(1, int(abs(to_deg - start) / (rate_deg_s * dt_s)))
    tips, torques = [], []
    for q in np.linspace(start, to_deg, n + 1)[1:]:
        cmd = np.zeros(2)
        cmd[knob], cmd[1 - knob] = q, other_deg
        s = plant.step(dt_s, cmd)
        tips.append(s.tip_deg[knob])
        torques.append(s.knob_torque_Nm[knob])
    return np.array(tips), np.array(torques)


def test_the_tip_does_not_depend_on_the_time_step() -> None:
    a, b = make_nitinol_plant(), make_nitinol_plant()
    ta, _ = _ramp(a, 0, 90.0, dt_s=0.0005)
    tb, _ = _ramp(b, 0, 90.0, dt_s=0.004)
    assert abs(ta[-1] - tb[-1]) < 0.3


def test_two_plants_driven_alike_answer_alike() -> None:
    a, b = make_nitinol_plant(), make_nitinol_plant()
    for q in np.linspace(0.0, 80.0, 150):
        sa, sb = a.step(0.002, np.array([q, -0.5 * q])), b.step(0.002, np.array([q, -0.5 * q]))
    assert np.array_equal(sa.tip_deg, sb.tip_deg)
    assert np.array_equal(sa.knob_torque_Nm, sb.knob_torque_Nm)


def test_equal_lumen_offsets_bend_alike_both_ways() -> None:
    even = {"offset_ratio_neg": 1.0}
    up, down = make_nitinol_plant(knobs=[even, even]), make_nitinol_plant(knobs=[even, even])
    tu, qu = _ramp(up, 0, 80.0)
    td, qd = _ramp(down, 0, -80.0)
    assert tu[-1] == pytest.approx(-td[-1], abs=1e-6)
    assert qu[-1] == pytest.approx(-qd[-1], abs=1e-9)


def test_the_nearer_lumen_bends_the_tip_further() -> None:
    plant, mirror = make_nitinol_plant(), make_nitinol_plant()
    up, _ = _ramp(plant, 0, 80.0)
    down, _ = _ramp(mirror, 0, -80.0)
    assert -down[-1] > up[-1] + 1.0  # offset_ratio_neg 0.9: the negative side's arm is shorter


def test_reset_returns_to_straight_and_unloaded() -> None:
    plant = make_nitinol_plant()
    _ramp(plant, 0, 90.0)
    _ramp(plant, 1, -70.0, other_deg=90.0)
    plant.reset()
    s = plant.step(0.001, np.zeros(2))
    assert np.array_equal(s.tip_deg, np.zeros(2))
    assert np.array_equal(s.knob_torque_Nm, np.zeros(2))
    assert plant.fraction == 0.0


def test_the_tip_stays_still_in_the_dead_zone() -> None:
    tips, _ = _ramp(make_nitinol_plant(), 0, 15.0)
    assert np.all(tips == 0.0)


def test_the_spine_transforms_under_load_and_reverts_when_released() -> None:
    plant = make_nitinol_plant()
    _ramp(plant, 0, 90.0)
    assert plant.fraction > 0.1
    _ramp(plant, 0, 0.0)
    assert plant.fraction == 0.0


def test_the_spine_holds_the_tip_after_a_reversal_beyond_the_tendons_share() -> None:
    """The flag: at the reversal the tube's moment must fall to its lower plateau before the tip
    comes back, so the tip holds longer than with a spine whose plateaus nearly meet."""
    wide, narrow = make_nitinol_plant(), make_nitinol_plant(
        knobs=[{"lower_plateau_MPa": 470.0}, {"lower_plateau_MPa": 470.0}])
    holds = []
    for plant in (wide, narrow):
        _ramp(plant, 0, 90.0)
        tips, _ = _ramp(plant, 0, 70.0)
        holds.append(tips[0] - tips[-1])
    assert holds[0] < holds[1] - 3.0


def test_a_colder_spine_bends_further_at_the_same_knob() -> None:
    body, room = make_nitinol_plant(), make_nitinol_plant(temperature_C=22.0)
    tb, _ = _ramp(body, 0, 80.0)
    tr, _ = _ramp(room, 0, 80.0)
    assert tr[-1] > tb[-1] + 1.0


def test_a_faster_knob_meets_more_film_drag() -> None:
    slow, fast = make_nitinol_plant(), make_nitinol_plant()
    _, qs = _ramp(slow, 0, 70.0, rate_deg_s=5.0)
    _, qf = _ramp(fast, 0, 70.0, rate_deg_s=80.0)
    assert qf[-1] > qs[-1] + 0.002


def test_a_bent_other_plane_adds_friction_to_this_one() -> None:
    austenite = {"upper_plateau_MPa": 3000.0, "lower_plateau_MPa": 2000.0}  # never transforms
    straight = make_nitinol_plant(knobs=[austenite, austenite])
    bent = make_nitinol_plant(knobs=[austenite, austenite])
    _ramp(bent, 1, 70.0)
    _, qs = _ramp(straight, 0, 80.0)
    _, qb = _ramp(bent, 0, 80.0, other_deg=70.0)
    assert qb[-1] > qs[-1]


def test_a_spine_transformed_by_the_other_plane_is_softer_in_this_one() -> None:
    straight, bent = make_nitinol_plant(), make_nitinol_plant()
    _ramp(bent, 1, 70.0)
    ts, _ = _ramp(straight, 0, 60.0)
    tb, _ = _ramp(bent, 0, 60.0, other_deg=70.0)
    assert bent.fraction > 0.0
    assert tb[-1] > ts[-1] + 2.0


def test_more_slack_widens_the_dead_zone() -> None:
    plain, slack = make_nitinol_plant(), make_nitinol_plant()
    slack.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    tp, _ = _ramp(plain, 0, 35.0)
    ts, _ = _ramp(slack, 0, 35.0)
    assert ts[-1] < tp[-1] - 1.0


def test_a_curved_sheath_takes_more_torque() -> None:
    plain, curved = make_nitinol_plant(), make_nitinol_plant(sheath_curvature_deg=90.0)
    _, qp = _ramp(plain, 0, 80.0)
    _, qc = _ramp(curved, 0, 80.0)
    assert qc[-1] > qp[-1]


@pytest.mark.parametrize(("dt_s", "knob"), [(-0.001, [0.0, 0.0]), (0.001, [math.nan, 0.0]),
                                            (0.001, [1.0]), (0.001, "ab")])
def test_bad_step_input_is_refused(dt_s: float, knob: object) -> None:
    with pytest.raises(ValueError, match="dt_s|knob_deg"):
        make_nitinol_plant().step(dt_s, knob)


@pytest.mark.parametrize(("params", "message"), [
    ({"knobs": [{"slack_pos_mm": -1.0}, {}]}, "slack_pos_mm must be finite"),
    ({"knobs": [{"gold": 1.0}, {}]}, "unknown knob constant"),
    ({"knobs": [{}]}, "knobs must be a list of 2"),
    ({"knobs": [{"backbone_id_mm": 3.0}, {}]}, "backbone_id_mm"),
    ({"temperature_C": -40.0}, "not superelastic"),
    ({"sheath_curvature_deg": -5.0}, "sheath_curvature_deg"),
])
def test_bad_constants_are_refused_in_one_line(params: dict[str, Any], message: str) -> None:
    with pytest.raises(PlantLoadError, match=message) as err:
        load_plant(SPEC, params)
    assert "\n" not in str(err.value)


def test_an_unknown_shape_change_is_refused() -> None:
    with pytest.raises(PlantLoadError, match="cannot reshape"):
        make_nitinol_plant().reshape(twist_deg=3.0)
