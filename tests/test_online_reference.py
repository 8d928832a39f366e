"""The estimator's reference: learned from the first ramps, re-learned while it settles."""

from __future__ import annotations

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
SETTLE = 6
"""Re-learnings the settling reference needs to agree with (off by default; session 14)."""


def ramp(edge_deg: float, slope: float = SLOPE) -> LoadedRamp:
    """A ramp (positive side) crossing LEVEL_A at ``edge_deg``."""
    return LoadedRamp(0, 1, edge_deg + 10.0, LEVEL_A + slope * 10.0, slope, 0.0, 0.0, 200, 0.003)


def settling_drift(options: EstimatorOptions) -> EdgeTracker:
    """A catheter warming up: 16 ramps whose crossing creeps 0.12 deg outward per ramp and
    whose slope flattens 1 % per ramp, then 20 ramps where it stays."""
    tracker = EdgeTracker(0, 1, options)
    for i in range(36):
        k = min(i, 15)
        tracker.update(ramp(EDGE_DEG + 0.12 * k, SLOPE * (1.0 - 0.01 * k)), EDGE_DEG)
    return tracker


def test_behaviour_settling_under_an_early_reference_is_not_followed() -> None:
    tracker = settling_drift(EstimatorOptions(settle_ramps=SETTLE))
    assert tracker.applied_deg == 0.0
    assert tracker.reference.settled and tracker.reference.relearned > 0


def test_with_the_reference_fixed_at_once_the_same_settling_is_followed() -> None:
    tracker = settling_drift(EstimatorOptions(settle_ramps=0))
    assert tracker.applied_deg > 1.0


def test_the_reference_settles_once_it_stops_moving() -> None:
    o = EstimatorOptions(settle_ramps=SETTLE)
    tracker = EdgeTracker(0, 1, o)
    for _ in range(o.baseline_ramps + o.settle_ramps - 1):
        tracker.update(ramp(EDGE_DEG), EDGE_DEG)
    assert not tracker.reference.settled and tracker.status()["state"] == "settling"
    tracker.update(ramp(EDGE_DEG), EDGE_DEG)
    assert tracker.reference.settled and tracker.status()["state"] == "tracking"


def test_a_change_while_the_reference_settles_is_followed_and_fixes_it() -> None:
    o = EstimatorOptions(settle_ramps=SETTLE)
    tracker = EdgeTracker(0, 1, o)
    for _ in range(o.baseline_ramps + 1):
        tracker.update(ramp(EDGE_DEG), EDGE_DEG)
    tracker.update(ramp(EDGE_DEG + 4.0), EDGE_DEG)
    tracker.update(ramp(EDGE_DEG + 4.2), EDGE_DEG)
    assert tracker.applied_deg > 3.5
    assert tracker.reference.settled


def after_two_steeper_ramps(options: EstimatorOptions) -> EdgeTracker:
    """A bend: ramps 12 % steeper, the edge 2.5 deg further out; the first ramp is read with
    the slope in use before it moved (inside the gate), the second with the new one."""
    tracker = EdgeTracker(0, 1, options)
    for _ in range(options.baseline_ramps + options.settle_ramps):
        tracker.update(ramp(EDGE_DEG), EDGE_DEG)
    for _ in range(2):
        tracker.update(ramp(EDGE_DEG + 2.5, 1.12 * SLOPE), EDGE_DEG)
    return tracker


def test_a_ramp_read_with_a_lagging_slope_is_read_again_once_the_slope_moved() -> None:
    tracker = after_two_steeper_ramps(EstimatorOptions(reread_on_slope_change=True))
    assert tracker.applied_deg > 2.0 and tracker.n_reread == 1


def test_without_reading_again_the_same_bend_waits_for_a_third_ramp() -> None:
    tracker = after_two_steeper_ramps(EstimatorOptions(reread_on_slope_change=False))
    assert tracker.applied_deg == 0.0


def test_steeper_ramps_while_settling_are_a_change_not_settling() -> None:
    o = EstimatorOptions(settle_ramps=SETTLE)
    tracker = EdgeTracker(0, 1, o)
    for _ in range(o.baseline_ramps + 1):
        tracker.update(ramp(EDGE_DEG), EDGE_DEG)
    for _ in range(8):  # a bend: 12 % more friction, the edge 1.2 deg out (inside the gate)
        tracker.update(ramp(EDGE_DEG + 1.2, 1.12 * SLOPE), EDGE_DEG)
    assert tracker.reference.settled and tracker.reference.relearned <= 1
    assert tracker.applied_deg > 0.8
