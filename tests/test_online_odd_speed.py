"""Ramps far off the reference's knob speed: their slopes count only once both tendons' ramps at
the reference's speed changed alike, and a slope beyond the bounds at such a speed is no
stuck knob (session 24, planetwist 1 without a change)."""

from __future__ import annotations

import dataclasses

import pytest

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
REFERENCE_SPEED = 20.0


def ramp(speed_deg_s: float = REFERENCE_SPEED, ratio: float = 1.0) -> LoadedRamp:
    """A ramp crossing LEVEL_A at the profile's edge (its window 10 deg out), ``ratio`` x the
    reference slope, at a knob speed."""
    base = LoadedRamp(0, 1, EDGE_DEG + 10.0, LEVEL_A + SLOPE * 10.0, ratio * SLOPE, 0.0, 0.0,
                      200, 0.003)
    return dataclasses.replace(base, speed_deg_s=speed_deg_s)


def knob(options: EstimatorOptions) -> tuple[EdgeTracker, EdgeTracker]:
    """Both edges of a knob with their references learned at the reference speed."""
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp(), EDGE_DEG, neg)
        neg.update(ramp(), EDGE_DEG, pos)
    return pos, neg


def slow_steep_after(options: EstimatorOptions, pos_ratio: float, neg_ratio: float
                     ) -> EdgeTracker:
    """The positive edge after one ramp of each tendon at the reference speed (``pos_ratio``,
    ``neg_ratio`` x its reference), then a slow ramp 1.6 x as steep."""
    pos, neg = knob(options)
    pos.update(ramp(ratio=pos_ratio), EDGE_DEG, neg)
    neg.update(ramp(ratio=neg_ratio), EDGE_DEG, pos)
    pos.update(ramp(8.0, 1.6), EDGE_DEG, neg)
    return pos


def test_a_slow_ramps_slope_counts_once_both_tendons_steepened_at_the_reference_speed() -> None:
    pos = slow_steep_after(EstimatorOptions(), 1.2, 1.2)
    assert pos.last_change == pytest.approx(0.6)


def test_one_tendons_steeper_ramp_leaves_a_slow_ramps_slope_out() -> None:
    pos = slow_steep_after(EstimatorOptions(), 1.0, 1.2)
    assert pos.last_change == pytest.approx(0.0)


def test_with_the_rule_off_one_tendons_steeper_ramp_lets_it_count() -> None:
    pos = slow_steep_after(EstimatorOptions(odd_speed_slopes_need_both=False), 1.0, 1.2)
    assert pos.last_change == pytest.approx(0.6)


def test_a_flat_ramp_at_the_velocity_limit_measures_nothing_without_a_warning() -> None:
    pos, neg = knob(EstimatorOptions())
    events = pos.update(ramp(113.0, 0.3), EDGE_DEG, neg)
    assert events == []
    assert (pos.n_refused, pos.n_odd_speed) == (0, 1)


def test_the_same_ramp_at_the_reference_speed_is_refused_with_a_warning() -> None:
    pos, neg = knob(EstimatorOptions())
    events = pos.update(ramp(REFERENCE_SPEED, 0.3), EDGE_DEG, neg)
    assert [name for _, name, _ in events] == ["online ramp refused"]


def test_with_the_rule_off_the_fast_flat_ramp_is_refused() -> None:
    pos, neg = knob(EstimatorOptions(odd_speed_not_refused=False))
    events = pos.update(ramp(113.0, 0.3), EDGE_DEG, neg)
    assert [name for _, name, _ in events] == ["online ramp refused"]


def test_a_slow_ramp_keeps_the_suspects_it_does_not_refuse() -> None:
    pos, neg = knob(EstimatorOptions())
    pos.update(dataclasses.replace(ramp(), u0_deg=EDGE_DEG + 13.0), EDGE_DEG, neg)  # +3 deg
    pos.update(ramp(113.0, 0.3), EDGE_DEG, neg)
    assert pos.suspects == [pytest.approx(3.0)]
