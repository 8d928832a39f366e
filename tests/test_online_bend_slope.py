"""A bend that moves no edge: beta grows with the loaded ramps' slope rise, omega with beta, by
the product's relation (session 22)."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
from support.profiles import DEVICE
from test_online_estimator import (
    EDGE_DEG,
    SLOPE,
    learned,
    learned_knob,
    ramp_with_edge,
    ramp_with_knee,
)

from tsmd.compensation import build_compensator
from tsmd.datasheet_bend import bend_relation
from tsmd.loop import ROW_COLUMNS
from tsmd.online import OnlineError, OnlineWorker
from tsmd.online.apply import bent_omega, shifted_knob
from tsmd.online.bend import (
    BendRelation,
    bend_targets,
    measure_bend_relation,
    sheet_bend_relation,
    slope_rise,
    with_bend_relation,
)
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.profile import (
    device_model_from_mapping,
    device_model_to_mapping,
    load_device_model,
    load_profile,
)

PROFILE = Path(__file__).resolve().parents[1] / "profiles" / "example-sim.yaml"


def calibration(edge_deg: float, gain: float, omega: float) -> Any:
    """A profile whose four tendons have the given (outward) edge and beta (x0 at 18 deg),
    and whose knobs have the given omega, other knob 0."""
    tp = SimpleNamespace(other_knob_deg=(-40.0, 0.0, 40.0), omega=omega,
                         dead_zone_pos_deg=(0.0, edge_deg, 0.0),
                         dead_zone_neg_deg=(0.0, -edge_deg, 0.0),
                         zero_load_pos_deg=(0.0, 18.0, 0.0), zero_load_neg_deg=(0.0, -18.0, 0.0),
                         backlash_gain_pos=(0.0, gain, 0.0), backlash_gain_neg=(0.0, gain, 0.0))
    return SimpleNamespace(knobs=(SimpleNamespace(tension_play=tp),) * 2)


def test_a_bend_that_moves_no_edge_gives_beta_per_slope_rise_and_omega_per_beta() -> None:
    straight = calibration(20.0, 0.17, 1.30)
    bent = calibration(19.8, 0.17 * 1.22, 1.30 * (1.0 - 0.2 * 0.22))
    relation = measure_bend_relation(straight, [bent], [(0.25, 0.25)])
    assert relation.gain_per_slope == pytest.approx(0.22 / 0.25)
    assert relation.omega_per_gain == pytest.approx(-0.2)
    assert relation.release_per_edge == 1.0  # no edge moved: the slack's


def test_without_slope_readings_a_bend_that_moves_no_edge_gives_no_relation() -> None:
    with pytest.raises(OnlineError, match="no bend moved an edge"):
        measure_bend_relation(calibration(20.0, 0.17, 1.3), [calibration(19.8, 0.2, 1.25)])


def _knob_steeper(ratio: float) -> tuple[Any, Any]:
    """Both tendons' ramps ``ratio`` x the reference, their edges where they were."""
    pos, neg = learned(), learned()
    for _ in range(6):
        pos.update(ramp_with_edge(EDGE_DEG, slope=ratio * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_with_edge(EDGE_DEG, slope=ratio * SLOPE), EDGE_DEG, pos)
    return pos, neg


def test_both_tendons_steeper_without_an_edge_move_read_their_rise() -> None:
    pos, _ = _knob_steeper(1.25)
    assert pos.applied_deg == 0.0
    assert slope_rise(pos) == pytest.approx(0.25, abs=0.01)


def test_slopes_within_the_same_slope_tolerance_read_no_rise() -> None:
    pos, _ = _knob_steeper(1.10)
    assert slope_rise(pos) == 0.0


def test_a_pooled_rise_beyond_the_tolerance_reads_while_one_tendon_sits_at_it() -> None:
    pos = SimpleNamespace(knob_change=0.19, knee_direction=0,
                          options=EstimatorOptions(same_slope_tolerance=0.15))
    assert slope_rise(pos) == pytest.approx(0.19)


def _gains(relation: BendRelation, ratio: float) -> Any:
    pos, neg = _knob_steeper(ratio)
    other_pos, other_neg = learned(), learned()
    trackers = {(0, 1): pos, (0, -1): neg, (1, 1): other_pos, (1, -1): other_neg}
    knobs = build_compensator(load_profile(PROFILE), "ours", 0.004).knobs
    return bend_targets(relation, trackers, knobs)


def test_a_steeper_knob_without_an_edge_move_grows_beta_by_the_relation_and_keeps_x0() -> None:
    zero, gain = _gains(BendRelation(1.0, 0.0, gain_per_slope=0.9), 1.25)
    assert gain[0][0] == pytest.approx(1.0 + 0.9 * 0.25, abs=0.01)
    assert zero[0] == (0.0, 0.0)
    assert gain[1] == (1.0, 1.0)  # the other knob's ramps did not change


def test_without_a_gain_per_slope_a_steeper_knob_moves_nothing() -> None:
    zero, gain = _gains(BendRelation(1.0, 0.06), 1.25)
    assert gain[0] == (1.0, 1.0) and zero[0] == pytest.approx((0.0, 0.0))


def test_omega_moves_by_the_relation_per_relative_beta_change() -> None:
    assert bent_omega(1.3, 0.2, 0.25, -0.2) == pytest.approx(1.3 * (1.0 - 0.2 * 0.25))


def test_without_omega_per_gain_omega_keeps_the_release_slope() -> None:
    assert bent_omega(1.3, 0.2, 0.25) == pytest.approx(1.3 * 0.75 / 0.8)


def test_a_shifted_knob_takes_the_relations_omega() -> None:
    knob = build_compensator(load_profile(PROFILE), "ours", 0.004).knobs[0]
    moved = shifted_knob(knob, (0.0, 0.0), (1.2, 1.2), (0.0, 0.0), omega_per_gain=-0.2)
    assert moved.omega == pytest.approx(knob.omega * (1.0 - 0.2 * 0.2), rel=1e-3)


def test_a_sheet_written_with_the_slope_terms_gives_them_back() -> None:
    device = with_bend_relation(load_device_model(DEVICE),
                                BendRelation(1.0, 0.0, gain_per_slope=0.8766,
                                             omega_per_gain=-0.2034))
    again = device_model_from_mapping(device_model_to_mapping(device))
    assert sheet_bend_relation(again) == BendRelation(1.0, 0.0, 0.877, -0.203)


def test_an_implausible_gain_per_slope_is_refused() -> None:
    with pytest.raises(OnlineError, match="implausible bend relation"):
        BendRelation(1.0, 0.0, gain_per_slope=-1.0)


def test_the_sheet_unit_reads_each_bends_slope_rise_under_its_straight_calibration() -> None:
    straight = calibration(20.0, 0.17, 1.30)
    asked: list[tuple[Any, float]] = []

    def calibrate_bent(bend_deg: float) -> Any:
        return straight if bend_deg == 0.0 else calibration(
            20.0, 0.17 * (1.0 + 0.004 * bend_deg), 1.30 * (1.0 - 0.0008 * bend_deg))

    def read_slopes(profile: Any, bend_deg: float) -> tuple[float, float]:
        asked.append((profile, bend_deg))
        return (0.005 * bend_deg, 0.005 * bend_deg)

    relation = bend_relation(calibrate_bent, read_slopes=read_slopes)
    assert [deg for _, deg in asked] == [30.0, 60.0, 90.0]
    assert all(profile is straight for profile, _ in asked)
    assert relation.gain_per_slope == pytest.approx(0.8)
    assert relation.omega_per_gain == pytest.approx(-0.2)


def test_where_bends_move_no_edge_a_knee_in_knee_mode_measures_nothing() -> None:
    pos, neg = learned_knob(EstimatorOptions(knee_places_edge=False))
    for _ in range(3):  # both ramps 1.25 x steeper, knees 2 deg further out
        pos.update(ramp_with_knee(EDGE_DEG + 2.0, 1.25 * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_with_knee(EDGE_DEG + 2.0, 1.25 * SLOPE), EDGE_DEG, pos)
    assert pos.knee_mode and not pos.suspects and pos.applied_deg == 0.0
    assert pos.status()["odd_knee_ramps"] >= 1


def test_a_worker_whose_products_bends_move_no_edge_leaves_the_knee_out() -> None:
    comp = build_compensator(load_profile(PROFILE), "ours", 0.004)
    worker = OnlineWorker(comp, 0.004, ROW_COLUMNS, bend=BendRelation(1.0, 0.0, 1.07))
    assert not worker.trackers[(0, 1)].options.knee_places_edge
    plain = OnlineWorker(comp, 0.004, ROW_COLUMNS, bend=BendRelation(1.2, 0.06))
    assert plain.trackers[(0, 1)].options.knee_places_edge
