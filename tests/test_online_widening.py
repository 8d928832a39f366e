"""A ramp whose slope disagrees with the slope in use reads a widening when its crossings with
the reference's slope and with its own both lie outward beyond the gate (a slack or a bend
widens the dead zone whatever the slope; the slope in use lags a change)."""

from __future__ import annotations

import numpy as np
import pytest

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
WINDOW_DEG = 10.0


def ramp_with_edge(edge_deg: float, slope: float) -> LoadedRamp:
    """A ramp of ``slope`` whose crossing of LEVEL_A is at ``edge_deg`` (positive side); with
    the reference's slope its crossing reads ``WINDOW_DEG * (1 - slope / SLOPE)`` further."""
    return LoadedRamp(0, 1, edge_deg + WINDOW_DEG, LEVEL_A + slope * WINDOW_DEG, slope, 0.0,
                      0.0, 200, 0.003)


def learned(options: EstimatorOptions) -> EdgeTracker:
    tracker = EdgeTracker(0, 1, options)
    for _ in range(options.baseline_ramps + options.settle_ramps):
        tracker.update(ramp_with_edge(EDGE_DEG, SLOPE), EDGE_DEG)
    return tracker


def test_a_steeper_ramp_reading_out_with_both_slopes_is_a_suspect_at_the_nearer() -> None:
    tracker = learned(EstimatorOptions())
    tracker.update(ramp_with_edge(EDGE_DEG + 6.0, 1.3 * SLOPE), EDGE_DEG)  # own 6, ref 3
    assert tracker.suspects == [pytest.approx(3.0)]
    assert tracker.status()["widened_ramps"] == 1 and tracker.n_odd_slope == 0


def test_two_odd_slope_ramps_reading_a_widening_are_followed() -> None:
    tracker = learned(EstimatorOptions())
    tracker.update(ramp_with_edge(EDGE_DEG + 6.0, 1.3 * SLOPE), EDGE_DEG)  # nearer: 3.0
    tracker.update(ramp_with_edge(EDGE_DEG + 4.0, 0.8 * SLOPE), EDGE_DEG)  # nearer: 4.0
    assert tracker.applied_deg == pytest.approx(3.5)


def test_a_steeper_ramp_reading_in_with_the_reference_slope_measures_nothing() -> None:
    tracker = learned(EstimatorOptions())
    tracker.update(ramp_with_edge(EDGE_DEG + 4.0, 1.3 * SLOPE), EDGE_DEG)  # own 4, ref 1
    assert np.isnan(tracker.last_measurement_deg) and tracker.suspects == []
    assert tracker.n_odd_slope == 1 and tracker.n_widened == 0


def test_without_the_rule_an_odd_slope_ramp_reading_out_measures_nothing() -> None:
    tracker = learned(EstimatorOptions(odd_slopes_read_widening=False))
    tracker.update(ramp_with_edge(EDGE_DEG + 6.0, 1.3 * SLOPE), EDGE_DEG)
    assert np.isnan(tracker.last_measurement_deg) and tracker.suspects == []
    assert tracker.n_odd_slope == 1
