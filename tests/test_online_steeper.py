"""A ramp steeper than the slope in use reads the crossing with its own slope when the knob's
other tendon's last ramp was steeper too (the sheath's friction rose on both tendons: a bend,
which the slope in use follows two ramps per edge late)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
WINDOW_DEG = 10.0
SPEED_DEG_S = 20.0


def ramp_with_edge(edge_deg: float, slope: float, side: int = 1,
                   speed_deg_s: float = SPEED_DEG_S) -> LoadedRamp:
    """A ramp of ``slope`` whose crossing of LEVEL_A is at ``edge_deg`` outward; with the
    reference's slope its crossing reads ``WINDOW_DEG * (1 - slope / SLOPE)`` further."""
    return LoadedRamp(0, side, edge_deg + WINDOW_DEG, LEVEL_A + slope * WINDOW_DEG, slope, 0.0,
                      0.0, 200, 0.003, speed_deg_s=speed_deg_s)


def learned(options: EstimatorOptions, side: int = 1) -> EdgeTracker:
    tracker = EdgeTracker(0, side, options)
    for _ in range(options.baseline_ramps + options.settle_ramps):
        tracker.update(ramp_with_edge(EDGE_DEG, SLOPE, side), side * EDGE_DEG)
    return tracker


def pair(options: EstimatorOptions, partner_slope: float) -> EdgeTracker:
    """A learned positive edge whose negative partner's last ramp had ``partner_slope``."""
    tracker, partner = learned(options), learned(options, -1)
    partner.update(ramp_with_edge(EDGE_DEG, partner_slope, -1), -EDGE_DEG, tracker)
    tracker.partner = partner
    return tracker


def test_a_steeper_ramp_of_a_steeper_knob_is_a_suspect_at_its_own_slope() -> None:
    tracker = pair(EstimatorOptions(), 1.3 * SLOPE)
    tracker.update(ramp_with_edge(EDGE_DEG + 3.0, 1.3 * SLOPE), EDGE_DEG)  # own 3, ref 0
    assert tracker.suspects == [pytest.approx(3.0)]
    assert tracker.status()["steeper_ramps"] == 1


def test_a_steeper_ramp_whose_partner_was_not_steeper_measures_nothing() -> None:
    tracker = pair(EstimatorOptions(), SLOPE)
    tracker.update(ramp_with_edge(EDGE_DEG + 3.0, 1.3 * SLOPE), EDGE_DEG)
    assert np.isnan(tracker.last_measurement_deg) and tracker.suspects == []
    assert tracker.n_steeper == 0


def test_a_steeper_ramp_at_an_odd_speed_measures_nothing() -> None:
    tracker = pair(EstimatorOptions(), 1.3 * SLOPE)
    slow = replace(ramp_with_edge(EDGE_DEG + 3.0, 1.3 * SLOPE), speed_deg_s=SPEED_DEG_S / 3)
    tracker.update(slow, EDGE_DEG)
    assert tracker.suspects == [] and tracker.n_steeper == 0


def test_a_steeper_knob_reading_within_the_gate_with_its_own_slope_measures_nothing() -> None:
    tracker = pair(EstimatorOptions(), 1.3 * SLOPE)
    tracker.update(ramp_with_edge(EDGE_DEG + 1.0, 1.3 * SLOPE), EDGE_DEG)
    assert tracker.suspects == [] and tracker.n_steeper == 0


def test_without_the_rule_a_steeper_knobs_ramp_reading_in_measures_nothing() -> None:
    tracker = pair(EstimatorOptions(steeper_knob_reads_own=False), 1.3 * SLOPE)
    tracker.update(ramp_with_edge(EDGE_DEG + 3.0, 1.3 * SLOPE), EDGE_DEG)
    assert np.isnan(tracker.last_measurement_deg) and tracker.suspects == []
