"""The wormeyelet plant: what its physics says, as behaviours of the plant alone."""

from __future__ import annotations

import math

import numpy as np
import pytest

from simrig.analysis import measure_dead_zone_backlash
from simrig.family import PLANT_ROLE, PLANT_SPECS, SCATTER, family_member
from simrig.plant import Plant, load_plant
from simrig.plants.wormeyelet import (
    NOMINAL_KNOBS,
    WormEyeletKnob,
    WormEyeletPlant,
    make_wormeyelet_plant,
)
from simrig.plants.wormeyelet.laws import damper_torque, eyelet_band, rope

SPEC = "simrig.plants.wormeyelet:make_wormeyelet_plant"
DT = 0.004


def _move(plant: WormEyeletPlant, start: tuple[float, float], end: tuple[float, float],
          seconds: float = 4.0) -> tuple[np.ndarray, np.ndarray]:
    """Smooth move of both knobs; (tip deg, knob torque N m) at its end."""
    n = round(seconds / DT)
    step = None
    for s in 0.5 - 0.5 * np.cos(np.linspace(0.0, math.pi, n)):
        step = plant.step(DT, np.array(start) + s * (np.array(end) - np.array(start)))
    assert step is not None
    return step.tip_deg, step.knob_torque_Nm


def _sweep(plant: WormEyeletPlant, amplitude: float = 90.0, cycles: float = 2.0
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Knob 1 swept at 0.04 Hz, knob 2 at 0: (knob deg, tip deg, torque N m) of knob 1."""
    t = np.arange(0.0, cycles / 0.04, 0.01)
    q = amplitude * np.sin(2.0 * math.pi * 0.04 * t)
    tip, tau = np.empty_like(q), np.empty_like(q)
    for i, x in enumerate(q):
        s = plant.step(0.01, np.array([x, 0.0]))
        tip[i], tau[i] = s.tip_deg[0], s.knob_torque_Nm[0]
    return q, tip, tau


def test_it_is_a_plant_loadable_by_spec() -> None:
    assert isinstance(load_plant(SPEC), Plant)


def test_the_tip_does_not_move_inside_the_slack() -> None:
    tip, _ = _move(make_wormeyelet_plant(), (0.0, 0.0), (12.0, 0.0))
    assert abs(tip[0]) < 0.05


def test_past_the_slack_the_knob_bends_the_tip_its_own_way_at_the_papers_slope() -> None:
    plant = make_wormeyelet_plant()
    tip60, _ = _move(plant, (0.0, 0.0), (60.0, 0.0))
    tip80, _ = _move(plant, (60.0, 0.0), (80.0, 0.0), 2.0)
    assert tip60[0] > 20.0
    assert 1.0 < (tip80[0] - tip60[0]) / 20.0 < 1.7


def test_the_measured_dead_zone_and_backlash_are_in_the_papers_range() -> None:
    q, tip, _ = _sweep(make_wormeyelet_plant())
    m = measure_dead_zone_backlash(q, tip)
    assert 10.0 < m.dead_zone_pos_deg < 30.0 and -30.0 < m.dead_zone_neg_deg < -10.0
    assert 10.0 < m.backlash_pos_deg < 30.0 and 10.0 < m.backlash_neg_deg < 30.0


def test_the_eyelets_widen_the_band_as_the_section_bends() -> None:
    low = eyelet_band(0.3, 6.0, 0.2, 0.0)
    high = eyelet_band(1.5, 6.0, 0.2, 0.0)
    assert (high[1] - high[0]) / 1.5 > 2.0 * (low[1] - low[0]) / 0.3


def test_the_other_planes_bend_widens_the_band() -> None:
    alone = eyelet_band(1.0, 6.0, 0.2, 0.0)
    crossed = eyelet_band(1.0, 6.0, 0.2, 1.2)
    assert crossed[1] > alone[1] and crossed[0] < alone[0]


def test_backlash_grows_with_the_sheaths_wrap() -> None:
    def backlash(wrap: float) -> float:
        knob = {"sheath_wrap_deg": wrap}
        q, tip, _ = _sweep(make_wormeyelet_plant(knobs=[knob, {}]))
        return measure_dead_zone_backlash(q, tip).backlash_pos_deg

    assert backlash(700.0) > backlash(400.0) + 3.0


def test_the_knob_torque_falls_at_a_reversal_because_the_wheel_back_drives_the_worm() -> None:
    plant = make_wormeyelet_plant()
    _, loaded = _move(plant, (0.0, 0.0), (80.0, 0.0))
    _, released = _move(plant, (80.0, 0.0), (78.0, 0.0), 0.5)
    assert released[0] < 0.7 * loaded[0]


def test_the_worm_loses_more_driving_than_back_driven() -> None:
    k = WormEyeletKnob()
    assert 0.0 < k.back_efficiency < k.drive_efficiency < 1.0
    assert WormEyeletKnob(worm_lead_deg=4.0).back_efficiency < 0.0  # self-locking


def test_the_damper_thins_at_speed() -> None:
    slow = damper_torque(0.1, 0.02, 1.5) / 0.1
    fast = damper_torque(3.0, 0.02, 1.5) / 3.0
    assert fast < 0.5 * slow and damper_torque(-1.0, 0.02, 1.5) < 0.0


def test_the_damper_shows_in_the_dead_zone_torque_in_proportion_to_speed() -> None:
    def torque_at(speed_deg_s: float) -> float:
        plant = make_wormeyelet_plant()
        tau = 0.0
        for i in range(50):
            tau = plant.step(0.01, np.array([speed_deg_s * 0.01 * (i + 1), 0.0])).knob_torque_Nm[0]
        return tau

    assert torque_at(20.0) > torque_at(5.0) + 0.002


def test_a_rope_pulled_through_the_contact_carries_the_capstan_ratio() -> None:
    state = rope(3.0, 0.0, 1.0, 3.2, 0.0, 0.03, 0.03, 4.0, 0.5)
    assert state.proximal_N == pytest.approx(4.0 * state.distal_N + 0.5)


def test_a_slack_rope_carries_nothing() -> None:
    state = rope(-1.0, 0.0, 1.0, 3.2, 0.0, 0.03, 0.03, 4.0, 0.5)
    assert state.proximal_N == 0.0 and state.distal_N == 0.0


def test_the_planes_are_coupled_by_the_other_bend() -> None:
    alone, _ = _move(make_wormeyelet_plant(), (0.0, 0.0), (80.0, 0.0))
    both, _ = _move(make_wormeyelet_plant(), (0.0, 0.0), (80.0, 80.0))
    assert both[0] < alone[0] - 1.0


def test_reset_returns_to_straight_and_the_same_path_repeats() -> None:
    plant = make_wormeyelet_plant()
    first, _ = _move(plant, (0.0, 0.0), (70.0, -50.0))
    plant.reset()
    assert np.all(plant.step(DT, np.zeros(2)).tip_deg == 0.0)
    again, _ = _move(plant, (0.0, 0.0), (70.0, -50.0))
    assert np.array_equal(first, again)


def test_more_slack_widens_the_dead_zone_mid_run() -> None:
    plant = make_wormeyelet_plant()
    before, _ = _move(plant, (0.0, 0.0), (40.0, 0.0))
    _move(plant, (40.0, 0.0), (0.0, 0.0))
    plant.reshape(slack_delta_mm=((0.5, 0.5), (0.5, 0.5)))
    after, _ = _move(plant, (0.0, 0.0), (40.0, 0.0))
    assert after[0] < before[0] - 3.0


def test_a_curved_shaft_raises_the_knob_torque() -> None:
    _, straight = _move(make_wormeyelet_plant(), (0.0, 0.0), (80.0, 0.0))
    _, curved = _move(make_wormeyelet_plant(sheath_curvature_deg=120.0), (0.0, 0.0), (80.0, 0.0))
    assert curved[0] > 1.1 * straight[0]


def test_a_unit_is_the_same_catheter_each_time_and_units_differ() -> None:
    a, b = family_member("wormeyelet", 101).build(), family_member("wormeyelet", 101).build()
    c = family_member("wormeyelet", 102).build()
    ta, _ = _move(a, (0.0, 0.0), (70.0, 0.0))  # type: ignore[arg-type]
    tb, _ = _move(b, (0.0, 0.0), (70.0, 0.0))  # type: ignore[arg-type]
    tc, _ = _move(c, (0.0, 0.0), (70.0, 0.0))  # type: ignore[arg-type]
    assert np.array_equal(ta, tb) and abs(tc[0] - ta[0]) > 0.1


def test_wormeyelet_is_registered_and_held_out() -> None:
    assert "wormeyelet" in PLANT_SPECS
    assert PLANT_ROLE["wormeyelet"] == "held-out"
    assert isinstance(family_member("wormeyelet", 101).build(), WormEyeletPlant)
    assert set(SCATTER["wormeyelet"]) <= set(family_member("wormeyelet", 0).params["knobs"][0])


def test_knob_2_is_not_knob_1() -> None:
    assert NOMINAL_KNOBS[0] != NOMINAL_KNOBS[1]


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"knobs": [{"worm": 1.0}, {}]}, "unknown wormeyelet knob constants: worm"),
        ({"knobs": [{}]}, "wormeyelet takes 2 knobs"),
        ({"knobs": [{"tendon_stiffness_N": 0.0}, {}]}, "tendon_stiffness_N must be > 0"),
        ({"knobs": [{}, {"sheath_friction": -0.1}]}, "sheath_friction must be >= 0"),
        ({"knobs": [{"contact_fraction": 1.0}, {}]}, "contact_fraction must be in"),
        ({"sheath_curvature_deg": -5.0}, "sheath_curvature_deg must be >= 0"),
    ],
)
def test_bad_constants_are_refused(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(ValueError, match=message):
        make_wormeyelet_plant(**kwargs)  # type: ignore[arg-type]


def test_bad_steps_are_refused() -> None:
    plant = make_wormeyelet_plant()
    with pytest.raises(ValueError, match="dt_s"):
        plant.step(-1.0, np.zeros(2))
    with pytest.raises(ValueError, match="knob_deg"):
        plant.step(DT, np.array([math.nan, 0.0]))
