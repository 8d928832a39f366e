"""A ramp at a knob speed far from the reference ramps' measures nothing: the sheath's friction,
and so the current on the loaded ramp, depends on the speed."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp, Stroke, loaded_ramp

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
REFERENCE_SPEED = 20.0


def ramp(edge_deg: float, speed_deg_s: float = REFERENCE_SPEED) -> LoadedRamp:
    """A ramp whose crossing of LEVEL_A is at ``edge_deg`` (positive side), run at a speed."""
    base = LoadedRamp(0, 1, edge_deg + 10.0, LEVEL_A + SLOPE * 10.0, SLOPE, 0.0, 0.0, 200, 0.003)
    return dataclasses.replace(base, speed_deg_s=speed_deg_s)


def after(options: EstimatorOptions, ramps: list[LoadedRamp]) -> EdgeTracker:
    tracker = EdgeTracker(0, 1, options)
    for _ in range(options.baseline_ramps):
        tracker.update(ramp(EDGE_DEG), EDGE_DEG)
    for r in ramps:
        tracker.update(r, EDGE_DEG)
    return tracker


def test_the_reference_learns_its_ramps_speed() -> None:
    assert after(EstimatorOptions(), []).speed_ref_deg_s == pytest.approx(REFERENCE_SPEED)


def test_slow_ramps_reading_in_measure_nothing() -> None:
    tracker = after(EstimatorOptions(), [ramp(EDGE_DEG - 3.0, 5.0)] * 3)
    assert tracker.applied_deg == 0.0
    assert tracker.n_odd_speed == 3


def test_slow_ramps_within_the_gate_leave_the_estimate() -> None:
    tracker = after(EstimatorOptions(), [ramp(EDGE_DEG + 1.0, 5.0)] * 5)
    assert tracker.estimate_deg == 0.0


def test_slow_ramps_reading_out_beyond_the_gate_are_followed() -> None:
    tracker = after(EstimatorOptions(), [ramp(EDGE_DEG + 3.0, 5.0)] * 3)
    assert tracker.applied_deg == pytest.approx(3.0, abs=0.01)


def test_the_same_ramps_at_the_reference_speed_are_followed() -> None:
    tracker = after(EstimatorOptions(), [ramp(EDGE_DEG - 3.0, 15.0)] * 3)
    assert tracker.applied_deg == pytest.approx(-3.0, abs=0.01)


def test_with_the_rule_off_slow_ramps_measure() -> None:
    tracker = after(EstimatorOptions(speed_ratio_max=0.0), [ramp(EDGE_DEG - 3.0, 5.0)] * 3)
    assert tracker.applied_deg == pytest.approx(-3.0, abs=0.01)


def test_the_loaded_ramp_carries_the_knob_speed_over_its_window() -> None:
    t = np.arange(0.0, 2.0, 0.004)
    pos = 20.0 * t
    current = 0.01 + 0.003 * np.maximum(pos - 10.0, 0.0)
    stroke = Stroke(0, 1, t, pos, pos, current, np.zeros_like(t), pos - pos[0])
    found = loaded_ramp(stroke, 10.0)
    assert isinstance(found, LoadedRamp)
    assert found.speed_deg_s == pytest.approx(20.0, rel=0.02)


def knob_after_slow_steep_ramps(options: EstimatorOptions) -> EdgeTracker:
    """Both edges learned at the reference speed, then one ramp each at 8 deg/s, 1.6 x as
    steep (a slow stroke's friction)."""
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp(EDGE_DEG), EDGE_DEG, neg)
        neg.update(ramp(EDGE_DEG), EDGE_DEG, pos)
    steep = dataclasses.replace(ramp(EDGE_DEG, 8.0), slope_A_per_deg=1.6 * SLOPE)
    neg.update(steep, EDGE_DEG, pos)
    pos.update(steep, EDGE_DEG, neg)
    return pos


def test_slow_ramps_slopes_leave_the_knob_out_of_knee_mode() -> None:
    pos = knob_after_slow_steep_ramps(EstimatorOptions())
    assert (pos.knee_direction, pos.slope_change) == (0, 0.0)


def test_with_every_slope_counting_slow_steep_ramps_set_knee_mode() -> None:
    pos = knob_after_slow_steep_ramps(EstimatorOptions(slopes_at_reference_speed=False))
    assert pos.knee_direction == 1


def test_slow_ramps_slopes_count_once_a_ramp_at_the_reference_speed_changed_alike() -> None:
    # either tendon's ramp, as until session 24 (both: tests/test_online_odd_speed.py)
    o = EstimatorOptions(odd_speed_slopes_need_both=False)
    pos, neg = EdgeTracker(0, 1, o), EdgeTracker(0, -1, o)
    for _ in range(o.baseline_ramps):
        pos.update(ramp(EDGE_DEG), EDGE_DEG, neg)
        neg.update(ramp(EDGE_DEG), EDGE_DEG, pos)
    neg.update(dataclasses.replace(ramp(EDGE_DEG), slope_A_per_deg=1.2 * SLOPE), EDGE_DEG, pos)
    pos.update(dataclasses.replace(ramp(EDGE_DEG, 8.0), slope_A_per_deg=1.6 * SLOPE), EDGE_DEG,
               neg)
    assert pos.last_change == pytest.approx(0.6)
