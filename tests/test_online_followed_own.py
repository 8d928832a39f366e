"""Once an edge followed a change, a crossing within the gate reads with the ramp's own slope
(EstimatorOptions.followed_reads_own): the reference slope is the tendon's before the change
(twistshaft 1, +0.5 mm slack: phi1's positive ramps 1.02-1.07 x the reference read +3.2..+3.7
deg with it, +3.6..+4.5 with their own; docs/online.md, session 27)."""

from __future__ import annotations

import pytest

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
STEEPER = 1.06
"""Steeper than the reference within the slope-in-use tolerance's shrink (one tendon only)."""
WINDOW_OUT_DEG = 20.0
"""The ramp's window centre this far outward of its crossing: a 6 % steeper ramp's crossing
with the reference slope lies 1.2 deg inward of its own."""


def ramp_crossing_at(edge_deg: float, slope: float = SLOPE) -> LoadedRamp:
    """A ramp of ``slope`` whose own line crosses LEVEL_A at ``edge_deg``."""
    return LoadedRamp(0, 1, edge_deg + WINDOW_OUT_DEG, LEVEL_A + slope * WINDOW_OUT_DEG, slope,
                      0.0, 0.0, 200, 0.003)


def followed_knob(options: EstimatorOptions) -> EdgeTracker:
    """The positive edge after following a +4.05 deg widening its other edge read too."""
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp_crossing_at(EDGE_DEG), EDGE_DEG, neg)
        neg.update(ramp_crossing_at(EDGE_DEG), EDGE_DEG, pos)
    neg.update(ramp_crossing_at(EDGE_DEG + 4.0), EDGE_DEG, pos)
    for m in (4.0, 4.1):
        pos.update(ramp_crossing_at(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == pytest.approx(4.05, abs=0.01)
    for _ in range(5):
        pos.update(ramp_crossing_at(EDGE_DEG + 4.6, STEEPER * SLOPE), EDGE_DEG, neg)
    return pos


def test_after_a_followed_change_steeper_ramps_read_with_their_own_slope() -> None:
    pos = followed_knob(EstimatorOptions(followed_reads_own=True))
    assert pos.applied_deg == pytest.approx(4.6, abs=0.02)
    assert pos.status()["followed_own_slope_ramps"] == 5


def test_without_the_rule_the_estimate_stays_where_the_follow_put_it() -> None:
    pos = followed_knob(EstimatorOptions(followed_reads_own=False))
    assert pos.applied_deg == pytest.approx(4.05, abs=0.01)
    assert pos.status()["followed_own_slope_ramps"] == 0


def test_before_any_followed_change_a_steeper_ramp_reads_between_the_slopes() -> None:
    options = EstimatorOptions(followed_reads_own=True)
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp_crossing_at(EDGE_DEG), EDGE_DEG, neg)
        neg.update(ramp_crossing_at(EDGE_DEG), EDGE_DEG, pos)
    pos.update(ramp_crossing_at(EDGE_DEG + 0.6, STEEPER * SLOPE), EDGE_DEG, neg)
    assert pos.last_measurement_deg == pytest.approx(0.0, abs=1e-6)  # the estimate lies between
    assert pos.status()["followed_own_slope_ramps"] == 0
