"""The edge-offset estimator: baseline, gating, bounds, hysteresis, freezes."""

from __future__ import annotations

import numpy as np
import pytest

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp
from tsmd.online.slopes import shrunk_ratio

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003


def ramp_with_edge(edge_deg: float, slope: float = SLOPE) -> LoadedRamp:
    """A ramp whose crossing of LEVEL_A is at ``edge_deg`` (positive side)."""
    u0 = edge_deg + 10.0
    return LoadedRamp(0, 1, u0, LEVEL_A + slope * 10.0, slope, 0.0, 0.0, 200, 0.003)


def ramp_through(edge_deg: float, slope: float) -> LoadedRamp:
    """A ramp of ``slope`` whose window centre carries the current of a reference-slope ramp
    with its edge at ``edge_deg``: the same engagement, only the slope measured differently."""
    return LoadedRamp(0, 1, edge_deg + 10.0, LEVEL_A + SLOPE * 10.0, slope, 0.0, 0.0, 200,
                      0.003)


def learned(options: EstimatorOptions | None = None) -> EdgeTracker:
    """A tracker whose reference is learned and settled on ramps at the profile's edge."""
    tracker = EdgeTracker(0, 1, options or EstimatorOptions())
    o = tracker.options
    for _ in range(o.baseline_ramps + o.settle_ramps):
        tracker.update(ramp_with_edge(EDGE_DEG), EDGE_DEG)
    assert not tracker.learning and tracker.reference.settled
    return tracker


def test_baseline_learns_the_level_at_the_calibrated_edge() -> None:
    tracker = learned()
    assert tracker.level_A == pytest.approx(LEVEL_A)
    assert tracker.applied_deg == 0.0


def test_step_change_is_followed_after_confirmation_with_a_warning() -> None:
    tracker = learned()
    events = tracker.update(ramp_with_edge(EDGE_DEG + 4.0), EDGE_DEG)
    assert tracker.applied_deg == 0.0  # one ramp alone is a suspect
    events += tracker.update(ramp_with_edge(EDGE_DEG + 4.2), EDGE_DEG)
    assert tracker.applied_deg == pytest.approx(4.1, abs=0.01)
    assert any(level == "warning" and "followed" in name for level, name, _ in events)


def test_no_change_no_drift_under_noise() -> None:
    tracker = learned()
    rng = np.random.default_rng(0)
    applied = []
    for _ in range(300):
        tracker.update(ramp_with_edge(EDGE_DEG + 0.3 * rng.standard_normal()), EDGE_DEG)
        applied.append(tracker.applied_deg)
    assert max(abs(a) for a in applied) <= 0.5  # hysteresis: noise does not move it


def test_an_isolated_outlier_is_not_followed() -> None:
    tracker = learned()
    for m in (0.1, 9.0, -0.1, 0.0, 7.0, 0.2):
        tracker.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG)
    assert tracker.applied_deg == 0.0


def test_a_change_beyond_the_bound_is_refused_with_a_warning() -> None:
    tracker = learned(EstimatorOptions(max_offset_deg=6.0))
    events = []
    for _ in range(4):
        events += tracker.update(ramp_with_edge(EDGE_DEG + 9.0), EDGE_DEG)
    assert tracker.applied_deg == 0.0
    assert any("beyond bounds" in name for _, name, _ in events)


def test_a_much_steeper_ramp_is_refused_and_voids_the_suspects() -> None:
    tracker = learned()
    tracker.update(ramp_with_edge(EDGE_DEG + 4.0), EDGE_DEG)  # a suspect
    events = tracker.update(ramp_with_edge(EDGE_DEG + 4.0, slope=5 * SLOPE), EDGE_DEG)
    assert any(level == "warning" and "refused" in name for level, name, _ in events)
    assert tracker.suspects == [] and tracker.status()["refused_ramps"] == 1
    tracker.update(ramp_with_edge(EDGE_DEG + 4.0), EDGE_DEG)  # a suspect again, not a second
    assert tracker.applied_deg == 0.0


def test_ramps_of_the_usual_slope_after_a_refused_one_measure_again() -> None:
    tracker = learned()
    tracker.update(ramp_with_edge(EDGE_DEG + 4.0, slope=0.25 * SLOPE), EDGE_DEG)
    for _ in range(2):  # a slack change, seen from the stroke across it on
        tracker.update(ramp_with_edge(EDGE_DEG + 4.0), EDGE_DEG)
    assert tracker.applied_deg == pytest.approx(4.0, abs=0.05)


def test_confidence_grows_with_agreeing_measurements() -> None:
    tracker = learned()
    confidences = []
    for _ in range(5):
        tracker.update(ramp_with_edge(EDGE_DEG + 0.1), EDGE_DEG)
        confidences.append(tracker.confidence)
    assert confidences == sorted(confidences)
    assert confidences[-1] > 0.8


def test_both_edges_of_a_knob_agreeing_confirm_a_change_at_once() -> None:
    pos, neg = learned(), learned()
    pos.update(ramp_with_edge(EDGE_DEG + 4.0), EDGE_DEG)
    assert not pos.agrees_with(neg)  # one suspect on one side only
    neg.update(ramp_with_edge(EDGE_DEG + 4.3), EDGE_DEG)
    assert pos.agrees_with(neg)
    pos.follow(pos.suspects[-1], "test")
    assert pos.applied_deg == pytest.approx(4.0)


def test_a_suspect_older_than_the_other_edges_ordinary_reading_agrees_with_nothing() -> None:
    pos, neg = learned(), learned()
    neg.update(ramp_with_edge(EDGE_DEG + 2.2), EDGE_DEG)
    pos.update(ramp_with_edge(EDGE_DEG + 0.3), EDGE_DEG)  # this edge read where it was after
    pos.update(ramp_with_edge(EDGE_DEG + 2.4), EDGE_DEG)
    assert pos.suspects and neg.suspects
    assert not pos.agrees_with(neg) and not neg.agrees_with(pos)


def test_without_fresh_agreement_a_suspect_before_the_other_edges_reading_agrees() -> None:
    options = EstimatorOptions(fresh_agreement=False)
    pos, neg = learned(options), learned(options)
    neg.update(ramp_with_edge(EDGE_DEG + 2.2), EDGE_DEG)
    pos.update(ramp_with_edge(EDGE_DEG + 0.3), EDGE_DEG)
    pos.update(ramp_with_edge(EDGE_DEG + 2.4), EDGE_DEG)
    assert pos.agrees_with(neg)


def test_edges_of_a_knob_that_disagree_confirm_nothing() -> None:
    pos, neg = learned(), learned()
    pos.update(ramp_with_edge(EDGE_DEG + 4.0), EDGE_DEG)
    neg.update(ramp_with_edge(EDGE_DEG - 3.0), EDGE_DEG)
    assert not pos.agrees_with(neg)


def test_one_ramp_with_an_odd_slope_measures_nothing() -> None:
    tracker = learned()
    tracker.update(ramp_through(EDGE_DEG, 1.3 * SLOPE), EDGE_DEG)  # its own slope: 2.3 deg
    assert np.isnan(tracker.last_measurement_deg)
    assert tracker.suspects == [] and tracker.status()["odd_slope_ramps"] == 1


def test_slopes_within_their_scatter_leave_the_edge_at_the_reference_slopes() -> None:
    tracker = learned()
    tol = tracker.options.slope_in_use_tolerance
    for share in (0.7, 0.9, 0.6, 0.8, 0.95, 0.7):  # persistently a little flatter
        tracker.update(ramp_through(EDGE_DEG, (1.0 - share * tol) * SLOPE), EDGE_DEG)
    assert abs(tracker.last_measurement_deg) < 0.3
    assert tracker.applied_deg == 0.0


def test_a_friction_change_is_followed_with_the_new_slope() -> None:
    tracker = learned()
    for _ in range(3):  # a bend: the ramp 2.5 x steeper and its edge 3 deg further out
        tracker.update(ramp_with_edge(EDGE_DEG + 3.0, slope=2.5 * SLOPE), EDGE_DEG)
    assert tracker.applied_deg == pytest.approx(3.0, abs=0.05)


def test_the_slope_in_use_does_not_jump_at_the_tolerance() -> None:
    tol = 0.15
    for edge in (1.0 + tol, 1.0 + 2 * tol, 1.0 - tol, 1.0 - 2 * tol):
        assert shrunk_ratio(edge + 1e-6, tol) == pytest.approx(shrunk_ratio(edge - 1e-6, tol),
                                                               abs=1e-4)
    assert shrunk_ratio(1.1, tol) == 1.0 and shrunk_ratio(2.5, tol) == 2.5


def test_a_slope_change_on_one_edge_alone_is_no_friction_change() -> None:
    pos, neg = learned(), learned()
    for _ in range(4):  # one tendon's ramps 25 % steeper, the other's as before
        pos.update(ramp_through(EDGE_DEG, 1.25 * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_through(EDGE_DEG, SLOPE), EDGE_DEG, pos)
    assert pos.applied_deg == 0.0 and pos.suspects == []


def test_a_friction_change_on_both_edges_is_followed() -> None:
    pos, neg = learned(), learned()
    for _ in range(4):  # a bend: both tendons' ramps 2.5 x steeper, edges 3 deg out
        pos.update(ramp_with_edge(EDGE_DEG + 3.0, slope=2.5 * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_with_edge(EDGE_DEG + 3.0, slope=2.5 * SLOPE), EDGE_DEG, pos)
    assert pos.applied_deg == pytest.approx(3.0, abs=0.05)
    assert neg.applied_deg == pytest.approx(3.0, abs=0.05)


def _both_edges_18_percent_steeper(options: EstimatorOptions) -> tuple[EdgeTracker, EdgeTracker]:
    """Both tendons' ramps 18 % steeper, their edges 3 deg further out (the lumped plant's
    60 deg bend: ramps 1.04-1.21 x, the calibration's edges +2.75..+3.4 deg)."""
    pos, neg = learned(options), learned(options)
    for _ in range(6):
        pos.update(ramp_with_edge(EDGE_DEG + 3.0, slope=1.18 * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_with_edge(EDGE_DEG + 3.0, slope=1.18 * SLOPE), EDGE_DEG, pos)
    return pos, neg


def test_a_small_friction_change_on_both_edges_is_followed_below_the_slope_tolerance() -> None:
    pos, neg = _both_edges_18_percent_steeper(EstimatorOptions(slope_in_use_tolerance=0.05))
    assert pos.applied_deg == pytest.approx(3.0, abs=0.05)
    assert neg.applied_deg == pytest.approx(3.0, abs=0.05)


def test_a_small_friction_change_within_the_slope_tolerance_measures_nothing() -> None:
    pos, _ = _both_edges_18_percent_steeper(EstimatorOptions(
        slope_in_use_tolerance=0.15, pooled_slope_change=False, steeper_knob_reads_own=False))
    assert pos.applied_deg == 0.0 and pos.status()["odd_slope_ramps"] > 0


def test_a_steeper_knob_reads_its_own_slope_where_the_slope_in_use_stays() -> None:
    pos, neg = _both_edges_18_percent_steeper(EstimatorOptions(slope_in_use_tolerance=0.15,
                                                               pooled_slope_change=False))
    assert pos.applied_deg == pytest.approx(3.0, abs=0.05)
    assert neg.applied_deg == pytest.approx(3.0, abs=0.05)
    assert pos.status()["steeper_ramps"] > 0


def test_a_friction_change_without_knees_scales_the_backlash_gain_by_the_slope() -> None:
    pos, _ = _both_edges_18_percent_steeper(
        EstimatorOptions(slope_in_use_tolerance=0.05, gain_from_slope_in_use=True))
    assert pos.knee_slopes == []
    assert pos.gain_ratio == pytest.approx(1.18, abs=0.01)


def test_without_gain_from_the_slope_in_use_the_backlash_gain_needs_knees() -> None:
    pos, _ = _both_edges_18_percent_steeper(
        EstimatorOptions(slope_in_use_tolerance=0.05, gain_from_slope_in_use=False))
    assert pos.gain_ratio == 1.0


def test_a_much_steeper_ramp_measures_on_both_edges_and_is_refused_on_one() -> None:
    pos, neg = learned(), learned()
    lone, usual = learned(), learned()
    for _ in range(4):  # a bend (both tendons 4 x steeper) against a blocked tendon (one)
        pos.update(ramp_with_edge(EDGE_DEG + 3.0, slope=4 * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_with_edge(EDGE_DEG + 3.0, slope=4 * SLOPE), EDGE_DEG, pos)
        lone.update(ramp_with_edge(EDGE_DEG + 3.0, slope=4 * SLOPE), EDGE_DEG, usual)
        usual.update(ramp_with_edge(EDGE_DEG), EDGE_DEG, lone)
    assert pos.applied_deg == pytest.approx(3.0, abs=0.05)
    assert lone.status()["refused_ramps"] == 4 and lone.applied_deg == 0.0


COUPLING_DEG = {-75.0: -0.6, -45.0: -0.3, -15.0: 0.0, 15.0: 0.2, 45.0: 0.7}
"""Where the current's edge sits, per angle of the other knob (zero mean over the bins)."""


def ramp_at_other(edge_deg: float, other_deg: float) -> LoadedRamp:
    return LoadedRamp(0, 1, edge_deg + 10.0, LEVEL_A + SLOPE * 10.0, SLOPE, other_deg, 0.0,
                      200, 0.003)


def estimates_under_coupling(seed: int, shift_deg: float, shift_from: int,
                             n_ramps: int) -> list[float]:
    """The estimate after each ramp of a static other-knob coupling with noise; every bin
    shifted by ``shift_deg`` from ramp ``shift_from`` on (within the gate: no confirmation)."""
    tracker = EdgeTracker(0, 1, EstimatorOptions())
    for _ in range(tracker.options.baseline_ramps + tracker.options.settle_ramps):
        tracker.update(ramp_at_other(EDGE_DEG, -15.0), EDGE_DEG)
    rng = np.random.default_rng(seed)
    others = list(COUPLING_DEG)
    estimates = []
    for i in range(n_ramps):
        other = others[int(rng.integers(len(others)))]
        shift = shift_deg if i >= shift_from else 0.0
        edge = EDGE_DEG + COUPLING_DEG[other] + shift + 0.3 * rng.standard_normal()
        tracker.update(ramp_at_other(edge, other), EDGE_DEG)
        estimates.append(tracker.estimate_deg)
    return estimates


@pytest.mark.parametrize("seed", range(4))
def test_a_static_other_knob_coupling_does_not_walk_the_estimate(seed: int) -> None:
    estimates = estimates_under_coupling(seed, 0.0, 0, 1000)
    block_means = [float(np.mean(estimates[i:i + 100])) for i in range(0, 1000, 100)]
    assert max(abs(b) for b in block_means) <= 0.15


@pytest.mark.parametrize("seed", range(4))
def test_a_common_shift_within_the_gate_goes_to_the_estimate_not_the_bins(seed: int) -> None:
    estimates = estimates_under_coupling(seed, 1.0, 300, 800)
    assert float(np.mean(estimates[500:])) == pytest.approx(1.0, abs=0.15)


def test_two_measurements_do_not_move_the_estimate_past_the_profile() -> None:
    tracker = learned()
    tracker.update(ramp_with_edge(EDGE_DEG + 0.1), EDGE_DEG)
    tracker.update(ramp_with_edge(EDGE_DEG + 1.2), EDGE_DEG)
    assert tracker.applied_deg == 0.0


def ramp_with_knee(knee_deg: float, slope: float = SLOPE) -> LoadedRamp:
    """A ramp whose stroke showed its knee at ``knee_deg`` (positive side); its crossing of
    LEVEL_A stays at the calibrated edge (a bend's steeper engagement reads inward there)."""
    return LoadedRamp(0, 1, EDGE_DEG + 10.0, LEVEL_A + slope * 10.0, slope, 0.0, 0.0, 200,
                      0.003, knee_deg, 0.01)


def learned_knob(options: EstimatorOptions | None = None) -> tuple[EdgeTracker, EdgeTracker]:
    """Both tendons of a knob past their baseline, knees at the calibrated edge."""
    o = options or EstimatorOptions()
    pos, neg = EdgeTracker(0, 1, o), EdgeTracker(0, -1, o)
    for _ in range(pos.options.baseline_ramps + pos.options.settle_ramps):
        pos.update(ramp_with_knee(EDGE_DEG), EDGE_DEG, neg)
        neg.update(ramp_with_knee(EDGE_DEG), EDGE_DEG, pos)
    return pos, neg


def test_the_first_steeper_ramp_of_both_tendons_places_the_edge_by_its_knee() -> None:
    pos, neg = learned_knob()  # a bend: both ramps 1.4 x steeper, knees 4 deg further out
    neg.update(ramp_with_knee(EDGE_DEG + 4.2, 1.4 * SLOPE), EDGE_DEG, pos)
    pos.update(ramp_with_knee(EDGE_DEG + 4.0, 1.4 * SLOPE), EDGE_DEG, neg)
    neg.update(ramp_with_knee(EDGE_DEG + 4.2, 1.4 * SLOPE), EDGE_DEG, pos)
    assert neg.knee_mode and neg.last_feature == "knee"  # the medians have not moved yet
    assert neg.agrees_with(pos) and neg.suspects[-1] == pytest.approx(4.2)


def test_one_steeper_ramp_of_one_tendon_alone_is_no_knee_mode() -> None:
    pos, neg = learned_knob()
    pos.update(ramp_with_knee(EDGE_DEG + 4.0, 1.4 * SLOPE), EDGE_DEG, neg)
    neg.update(ramp_with_knee(EDGE_DEG, SLOPE), EDGE_DEG, pos)
    assert not pos.knee_mode and not neg.knee_mode


def test_a_knee_inward_while_the_ramps_got_steeper_measures_nothing() -> None:
    pos, neg = learned_knob()  # the lumped plant's toe: steeper ramps, knees read inward
    for _ in range(3):
        pos.update(ramp_with_knee(EDGE_DEG - 4.0, 1.4 * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_with_knee(EDGE_DEG - 4.0, 1.4 * SLOPE), EDGE_DEG, pos)
    assert neg.knee_mode and neg.suspects == [] and neg.applied_deg == 0.0
    assert neg.status()["odd_knee_ramps"] == 3


def test_a_bend_followed_by_its_knee_leaves_the_zero_load_point_when_asked() -> None:
    pos, neg = learned_knob(EstimatorOptions(keep_zero_load_in_bend=True))  # a bend: both
    # ramps 1.4 x steeper, knees 4 deg further out
    for _ in range(3):
        pos.update(ramp_with_knee(EDGE_DEG + 4.0, 1.4 * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_with_knee(EDGE_DEG + 4.0, 1.4 * SLOPE), EDGE_DEG, pos)
    assert neg.last_feature == "knee" and neg.applied_deg == pytest.approx(4.0)
    assert neg.zero_load_deg == 0.0


def test_a_slack_change_moves_the_zero_load_point_with_the_edge() -> None:
    tracker = learned()
    tracker.update(ramp_with_edge(EDGE_DEG + 4.0), EDGE_DEG)
    tracker.update(ramp_with_edge(EDGE_DEG + 4.2), EDGE_DEG)
    assert tracker.last_feature == "crossing"
    assert tracker.zero_load_deg == tracker.applied_deg == pytest.approx(4.1, abs=0.01)


def test_by_default_a_bend_moves_the_zero_load_point_with_the_edge() -> None:
    pos, neg = learned_knob()
    for _ in range(3):
        pos.update(ramp_with_knee(EDGE_DEG + 4.0, 1.4 * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_with_knee(EDGE_DEG + 4.0, 1.4 * SLOPE), EDGE_DEG, pos)
    assert neg.last_feature == "knee" and neg.zero_load_deg == neg.applied_deg != 0.0


def test_the_first_knee_of_a_bend_on_both_tendons_is_a_bend_suspect() -> None:
    pos, neg = learned_knob()
    neg.update(ramp_with_knee(EDGE_DEG, 1.4 * SLOPE), EDGE_DEG, pos)  # slope only, no knee mode
    pos.update(ramp_with_knee(EDGE_DEG + 4.0, 1.4 * SLOPE), EDGE_DEG, neg)
    assert pos.bend_suspect and pos.suspects == [pytest.approx(4.0)]


def test_a_later_lone_knee_of_a_bend_is_no_bend_suspect() -> None:
    pos, neg = learned_knob()
    for knee in (4.0, 4.0, 4.0, 7.0):  # followed at 4, then one knee 3 deg further out
        neg.update(ramp_with_knee(EDGE_DEG + knee, 1.4 * SLOPE), EDGE_DEG, pos)
        pos.update(ramp_with_knee(EDGE_DEG + knee, 1.4 * SLOPE), EDGE_DEG, neg)
    assert pos.applied_deg == pytest.approx(4.0) and not pos.bend_suspect


def _sides_steeper(pos_ratio: float, neg_ratio: float, pooled: bool) -> tuple[EdgeTracker,
                                                                               EdgeTracker]:
    """Both edges' ramps steeper by the given ratios, their edges 3 deg further out."""
    o = EstimatorOptions(pooled_slope_change=pooled)
    pos, neg = learned(o), learned(o)
    for _ in range(6):
        pos.update(ramp_with_edge(EDGE_DEG + 3.0, slope=pos_ratio * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_with_edge(EDGE_DEG + 3.0, slope=neg_ratio * SLOPE), EDGE_DEG, pos)
    return pos, neg


def test_a_friction_change_read_unevenly_by_the_two_sides_is_followed_further_pooled(
        ) -> None:
    pooled = _sides_steeper(1.12, 1.04, pooled=True)  # lumped 103 phi2 after a bend
    each = _sides_steeper(1.12, 1.04, pooled=False)
    for a, b in zip(pooled, each, strict=True):
        assert a.applied_deg > b.applied_deg + 0.4


def test_one_steeper_side_with_a_barely_changed_partner_moves_no_slope_in_use() -> None:
    pos, neg = learned(), learned()
    for _ in range(6):
        pos.update(ramp_through(EDGE_DEG, 1.25 * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_through(EDGE_DEG, 1.01 * SLOPE), EDGE_DEG, pos)
    assert pos.applied_deg == 0.0 and neg.applied_deg == 0.0


def steeper_at_the_same_edge(ratio: float) -> LoadedRamp:
    """A ramp ``ratio`` x the reference slope whose own line still meets LEVEL_A at EDGE_DEG,
    with its window centre 15 deg out (as the worker's)."""
    slope = ratio * SLOPE
    return LoadedRamp(0, 1, EDGE_DEG + 15.0, LEVEL_A + slope * 15.0, slope, 0.0, 0.0, 200,
                      0.003)


def test_an_inward_crossing_on_a_steeper_ramp_measures_nothing() -> None:
    tracker, partner = learned(EstimatorOptions(refuse_inward_on_steeper=True)), learned()
    for _ in range(2):  # 13 % steeper, the knob's other tendon not yet: the slope in use
        tracker.update(steeper_at_the_same_edge(1.13), EDGE_DEG, partner)  # stays, ~2 deg in
    assert tracker.applied_deg == 0.0 and tracker.suspects == []
    assert tracker.status()["odd_crossing_ramps"] == 2


def test_without_the_rule_a_steeper_ramp_moves_the_edge_inward() -> None:
    tracker = learned(EstimatorOptions(refuse_inward_on_steeper=False, partner_confirms=False))
    partner = learned()
    for _ in range(2):
        tracker.update(steeper_at_the_same_edge(1.13), EDGE_DEG, partner)
    assert tracker.applied_deg < -1.5


def test_an_inward_crossing_on_a_ramp_of_the_usual_slope_is_still_followed() -> None:
    tracker = learned(EstimatorOptions(refuse_inward_on_steeper=True))
    for _ in range(2):
        tracker.update(ramp_with_edge(EDGE_DEG - 3.0), EDGE_DEG)
    assert tracker.applied_deg == pytest.approx(-3.0, abs=0.05)


def test_an_inward_crossing_after_the_knobs_ramps_got_steeper_measures_nothing() -> None:
    tracker, partner = (learned(EstimatorOptions(refuse_inward_on_steeper=True)),
                        learned(EstimatorOptions(refuse_inward_on_steeper=True)))
    for _ in range(3):  # both tendons 20 % steeper at the same edge: the slope in use follows
        partner.update(steeper_at_the_same_edge(1.2), EDGE_DEG, tracker)
        tracker.update(steeper_at_the_same_edge(1.2), EDGE_DEG, partner)
    inward = LoadedRamp(0, 1, EDGE_DEG + 12.0, LEVEL_A + 1.2 * SLOPE * 15.0, 1.2 * SLOPE, 0.0,
                        0.0, 200, 0.003)  # the same line 3 deg further in
    for _ in range(2):
        tracker.update(inward, EDGE_DEG, partner)
    assert tracker.applied_deg == 0.0 and tracker.status()["odd_crossing_ramps"] == 2
