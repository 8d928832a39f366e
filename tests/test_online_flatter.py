"""Ramps flatter than the reference read the crossing between the two slopes' readings
(EstimatorOptions.flatter_reads_between): a softer catheter does not move the edge."""

from __future__ import annotations

import pytest

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp
from tsmd.online.slopes import nearest_between

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
WINDOW_DEG = 10.0
"""How far beyond the edge the ramp's window centre sits."""


def ramp(shift_deg: float = 0.0, slope_ratio: float = 1.0) -> LoadedRamp:
    """A ramp moved ``shift_deg`` outward whose slope turned by ``slope_ratio`` about its
    window's centre (the current there unchanged)."""
    return LoadedRamp(0, 1, EDGE_DEG + shift_deg + WINDOW_DEG, LEVEL_A + SLOPE * WINDOW_DEG,
                      SLOPE * slope_ratio, 0.0, 0.0, 200, 0.003)


def run_knob(options: EstimatorOptions, shift_deg: float, slope_ratio: float,
             ramps: int = 8) -> tuple[EdgeTracker, EdgeTracker]:
    """Both edges of a knob: references learned on the profile's ramp, then ``ramps`` ramps
    per edge moved and turned alike."""
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp(), EDGE_DEG, neg)
        neg.update(ramp(), EDGE_DEG, pos)
    for _ in range(ramps):
        pos.update(ramp(shift_deg, slope_ratio), EDGE_DEG, neg)
        neg.update(ramp(shift_deg, slope_ratio), EDGE_DEG, pos)
    return pos, neg


def test_flatter_ramps_about_their_centre_leave_the_edges_in_place() -> None:
    pos, neg = run_knob(EstimatorOptions(), 0.0, 0.9)
    assert (pos.applied_deg, neg.applied_deg) == (0.0, 0.0)
    assert pos.estimate_deg == pytest.approx(0.0, abs=1e-9)
    assert pos.status()["between_ramps"] > 0


def test_without_the_rule_flatter_ramps_move_the_edges_inward() -> None:
    pos, neg = run_knob(EstimatorOptions(flatter_reads_between=False), 0.0, 0.9)
    assert pos.applied_deg == pytest.approx(-WINDOW_DEG * (1 / 0.9 - 1), abs=0.01)
    assert neg.applied_deg == pytest.approx(pos.applied_deg)


def test_a_widening_on_flatter_ramps_is_followed_within_the_two_readings() -> None:
    pos, neg = run_knob(EstimatorOptions(), 3.0, 0.9)
    nearer = 3.0 - WINDOW_DEG * (1 / 0.9 - 1)
    for edge in (pos, neg):
        assert nearer - 0.01 <= edge.applied_deg <= 3.0 + 0.01


def test_steeper_ramps_read_with_the_slope_in_use_alone() -> None:
    on, _ = run_knob(EstimatorOptions(), 0.0, 1.1)
    off, _ = run_knob(EstimatorOptions(flatter_reads_between=False), 0.0, 1.1)
    assert on.applied_deg == off.applied_deg != 0.0


def test_nearest_between_is_the_target_inside_and_the_nearer_end_outside() -> None:
    assert nearest_between(-1.0, 0.5, 0.2) == 0.2
    assert nearest_between(0.5, -1.0, 2.0) == 0.5
    assert nearest_between(1.9, 3.0, 0.0) == 1.9
