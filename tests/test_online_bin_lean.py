"""A reading beyond the gate in an other-knob bin still learning, whose readings so far lean
its way, is that bin's lean, not a change (planetwist 3 without a change, docs/online.md
session 26)."""

from __future__ import annotations

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp
from tsmd.online.other_knob import OtherKnobBins

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
HOME_DEG = 40.0
"""The other knob's angle of the reference's ramps (a learned bin)."""
FAR_DEG = -40.0
"""The other knob's angle of a bin that has not learned yet."""


def ramp_at(edge_deg: float, other_deg: float) -> LoadedRamp:
    return LoadedRamp(0, 1, edge_deg + 10.0, LEVEL_A + SLOPE * 10.0, SLOPE, other_deg, 0.0,
                      200, 0.003)


def tracker_with_far_bin(options: EstimatorOptions, far_readings: list[float]) -> EdgeTracker:
    """Reference learned and settled at HOME_DEG, then ``far_readings`` (deg outward of the
    profile's edge) in the bin of FAR_DEG."""
    tracker = EdgeTracker(0, 1, options)
    for _ in range(options.baseline_ramps + options.settle_ramps):
        tracker.update(ramp_at(EDGE_DEG, HOME_DEG), EDGE_DEG)
    for r in far_readings:
        tracker.update(ramp_at(EDGE_DEG + r, FAR_DEG), EDGE_DEG)
    return tracker


def test_a_bin_one_short_of_learned_that_leans_one_way_gives_its_median() -> None:
    bins = OtherKnobBins(30.0, 3, 7)
    bins.teach(bins.key(40.0), 0.0)
    bins.teach(bins.key(40.0), 0.0)
    bins.teach(bins.key(40.0), 0.0)
    bins.teach(bins.key(-40.0), 1.4)
    bins.teach(bins.key(-40.0), 1.2)
    assert abs(bins.learning_lean_deg(-40.0, 1) - 1.3) < 1e-9
    assert bins.learning_lean_deg(-40.0, -1) == 0.0


def test_a_bin_with_readings_either_way_or_too_few_gives_no_lean() -> None:
    bins = OtherKnobBins(30.0, 3, 7)
    bins.teach(bins.key(-40.0), 1.4)
    assert bins.learning_lean_deg(-40.0, 1) == 0.0
    bins.teach(bins.key(-40.0), -0.2)
    assert bins.learning_lean_deg(-40.0, 1) == 0.0


def test_a_learned_bin_gives_no_learning_lean() -> None:
    bins = OtherKnobBins(30.0, 3, 7)
    for v in (1.4, 1.3, 1.5):
        bins.teach(bins.key(-40.0), v)
    assert bins.learning_lean_deg(-40.0, 1) == 0.0


def test_a_third_reading_further_out_in_a_leaning_bin_is_no_suspect() -> None:
    tracker = tracker_with_far_bin(EstimatorOptions(), [1.4, 1.35, 2.55])
    assert tracker.suspects == [] and tracker.n_bin_lean == 1
    assert tracker.bins.learned(tracker.bins.key(FAR_DEG))


def test_without_the_rule_the_third_reading_is_a_suspect() -> None:
    tracker = tracker_with_far_bin(EstimatorOptions(learning_bin_lean_holds=False),
                                   [1.4, 1.35, 2.55])
    assert len(tracker.suspects) == 1 and tracker.n_bin_lean == 0


def test_a_change_beyond_the_bins_lean_and_the_gate_stays_a_suspect_at_its_value() -> None:
    tracker = tracker_with_far_bin(EstimatorOptions(), [1.4, 1.35, 3.6])
    assert len(tracker.suspects) == 1 and abs(tracker.suspects[0] - 3.6) < 0.05


def test_a_reading_beyond_the_gate_in_a_bin_leaning_the_other_way_stays_a_suspect() -> None:
    tracker = tracker_with_far_bin(EstimatorOptions(), [-0.8, -0.6, 2.0])
    assert len(tracker.suspects) == 1 and tracker.n_bin_lean == 0
