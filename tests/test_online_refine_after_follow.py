"""The readings right after a followed change refine it, in other-knob bins still learning too
and without the dead band (EstimatorOptions.refine_after_follow, off): twistshaft 2, +0.5 mm
slack, phi1's positive edge was followed to +2.82 deg from one ramp and stayed there while the
ramps after it read +2.7..+3.8 in learning bins (docs/online.md, session 27)."""

from __future__ import annotations

import pytest

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003


def ramp_with_edge(edge_deg: float, other_deg: float = 0.0) -> LoadedRamp:
    return LoadedRamp(0, 1, edge_deg + 10.0, LEVEL_A + SLOPE * 10.0, SLOPE, other_deg, 0.0,
                      200, 0.003)


def followed(options: EstimatorOptions, later_deg: list[float],
             other_deg: float = 0.0) -> EdgeTracker:
    """The positive edge after a +4.05 deg widening both edges read, then ``later_deg``."""
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp_with_edge(EDGE_DEG), EDGE_DEG, neg)
        neg.update(ramp_with_edge(EDGE_DEG), EDGE_DEG, pos)
    neg.update(ramp_with_edge(EDGE_DEG + 4.0), EDGE_DEG, pos)
    for m in (4.0, 4.1):
        pos.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == pytest.approx(4.05, abs=0.01)
    for m in later_deg:
        pos.update(ramp_with_edge(EDGE_DEG + m, other_deg), EDGE_DEG, neg)
    return pos


def test_a_refinement_within_the_dead_band_after_a_follow_is_applied() -> None:
    pos = followed(EstimatorOptions(refine_after_follow=True), [4.4, 4.4, 4.4])
    assert pos.estimate_deg == pytest.approx(4.4, abs=0.01)
    assert pos.applied_deg == pytest.approx(4.4, abs=0.01)


def test_without_the_rule_the_dead_band_holds_the_follow() -> None:
    pos = followed(EstimatorOptions(refine_after_follow=False), [4.4, 4.4, 4.4])
    assert pos.estimate_deg == pytest.approx(4.4, abs=0.01)
    assert pos.applied_deg == pytest.approx(4.05, abs=0.01)


def test_once_the_window_after_the_follow_is_full_the_dead_band_holds_again() -> None:
    options = EstimatorOptions(refine_after_follow=True)
    pos = followed(options, [4.4] * options.window + [4.7] * 3)
    assert pos.estimate_deg == pytest.approx(4.7, abs=0.01)
    assert pos.applied_deg == pytest.approx(4.4, abs=0.01)


def test_readings_in_a_bin_still_learning_refine_the_follow() -> None:
    pos = followed(EstimatorOptions(refine_after_follow=True), [4.9, 4.9, 4.9], -50.0)
    assert pos.applied_deg == pytest.approx(4.9, abs=0.01)


def test_without_the_rule_a_learning_bin_keeps_its_readings_from_the_estimate() -> None:
    pos = followed(EstimatorOptions(refine_after_follow=False), [4.9, 4.9], -50.0)
    assert pos.estimate_deg == pytest.approx(4.05, abs=0.01)
