"""The knob's other edge confirms the first change (tsmd.online.partner) and the backlash gain
waits for a followed change (EstimatorOptions.partner_confirms, gain_after_follow)."""

from __future__ import annotations

import pytest

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003


def ramp_with_edge(edge_deg: float, slope: float = SLOPE) -> LoadedRamp:
    """A ramp of ``slope`` whose crossing of LEVEL_A is at ``edge_deg``."""
    return LoadedRamp(0, 1, edge_deg + 10.0, LEVEL_A + slope * 10.0, slope, 0.0, 0.0, 200,
                      0.003)


def learned_knob(options: EstimatorOptions | None = None) -> tuple[EdgeTracker, EdgeTracker]:
    """Both edges of a knob with their references learned at the profile's edge."""
    o = options or EstimatorOptions()
    pos, neg = EdgeTracker(0, 1, o), EdgeTracker(0, -1, o)
    for _ in range(o.baseline_ramps):
        pos.update(ramp_with_edge(EDGE_DEG), EDGE_DEG, neg)
        neg.update(ramp_with_edge(EDGE_DEG), EDGE_DEG, pos)
    return pos, neg


def test_one_edge_moving_alone_does_not_leave_the_profile() -> None:
    pos, neg = learned_knob()
    neg.update(ramp_with_edge(EDGE_DEG - 0.2), EDGE_DEG, pos)  # the other edge reads in place
    for m in (2.0, 2.1, 2.0):
        pos.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == 0.0
    assert pos.status()["partner_held"] > 0


def test_without_the_rule_one_edge_moving_alone_is_followed() -> None:
    pos, neg = learned_knob(EstimatorOptions(partner_confirms=False))
    neg.update(ramp_with_edge(EDGE_DEG - 0.2), EDGE_DEG, pos)
    for m in (2.0, 2.1):
        pos.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == pytest.approx(2.05, abs=0.01)


def test_a_widening_the_other_edge_reads_too_is_followed() -> None:
    pos, neg = learned_knob()
    neg.update(ramp_with_edge(EDGE_DEG + 1.0), EDGE_DEG, pos)  # within its gate, but moved
    for m in (2.0, 2.1):
        pos.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == pytest.approx(2.05, abs=0.01)


def test_without_the_same_way_rule_a_shift_the_other_edge_reads_is_followed() -> None:
    pos, neg = learned_knob(EstimatorOptions(partner_confirms_same_way=False))
    neg.update(ramp_with_edge(EDGE_DEG - 2.0), EDGE_DEG, pos)  # inward: the knob's axis shifted
    for m in (2.0, 2.1):
        pos.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == pytest.approx(2.05, abs=0.01)


def test_a_shift_is_not_followed_by_default() -> None:
    pos, neg = learned_knob()
    neg.update(ramp_with_edge(EDGE_DEG - 2.0), EDGE_DEG, pos)  # inward: the dead zone moved
    for m in (2.0, 2.1):
        pos.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == 0.0
    assert pos.status()["partner_held"] > 0


def test_with_the_same_way_rule_the_inward_edge_of_a_shift_is_not_followed() -> None:
    options = EstimatorOptions(partner_confirms_same_way=True)
    pos, neg = learned_knob(options)
    neg.update(ramp_with_edge(EDGE_DEG + 2.5), EDGE_DEG, pos)  # outward
    for m in (-2.0, -2.1):
        pos.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == 0.0


def test_with_the_same_way_rule_a_widening_is_followed() -> None:
    pos, neg = learned_knob(EstimatorOptions(partner_confirms_same_way=True))
    neg.update(ramp_with_edge(EDGE_DEG + 1.0), EDGE_DEG, pos)
    for m in (2.0, 2.1):
        pos.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == pytest.approx(2.05, abs=0.01)


def test_with_the_same_way_rule_a_narrowing_is_followed() -> None:
    pos, neg = learned_knob(EstimatorOptions(partner_confirms_same_way=True))
    neg.update(ramp_with_edge(EDGE_DEG - 1.0), EDGE_DEG, pos)
    for m in (-2.0, -2.1):
        pos.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == pytest.approx(-2.05, abs=0.01)


def test_after_a_followed_change_an_edge_corrects_on_its_own() -> None:
    pos, neg = learned_knob()
    neg.update(ramp_with_edge(EDGE_DEG + 4.0), EDGE_DEG, pos)
    for m in (4.0, 4.1):
        pos.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == pytest.approx(4.05, abs=0.01)
    neg.update(ramp_with_edge(EDGE_DEG + 0.1), EDGE_DEG, pos)  # the other edge reads in place
    for m in (2.0, 2.1):
        pos.update(ramp_with_edge(EDGE_DEG + m), EDGE_DEG, neg)
    assert pos.applied_deg == pytest.approx(2.05, abs=0.01)


def test_an_estimate_within_the_gate_stays_off_the_edge_while_the_other_edge_stays() -> None:
    pos, neg = learned_knob()
    for _ in range(5):
        neg.update(ramp_with_edge(EDGE_DEG), EDGE_DEG, pos)
        pos.update(ramp_with_edge(EDGE_DEG + 0.8), EDGE_DEG, neg)
    assert pos.estimate_deg == pytest.approx(0.8, abs=0.01)
    assert pos.applied_deg == 0.0


def test_an_estimate_within_the_gate_on_both_edges_is_applied() -> None:
    pos, neg = learned_knob()
    for _ in range(5):
        neg.update(ramp_with_edge(EDGE_DEG + 0.8), EDGE_DEG, pos)
        pos.update(ramp_with_edge(EDGE_DEG + 0.8), EDGE_DEG, neg)
    assert pos.applied_deg == pytest.approx(0.8, abs=0.01)
    assert neg.applied_deg == pytest.approx(0.8, abs=0.01)


def steeper_knob(options: EstimatorOptions, edge_move_deg: float) -> EdgeTracker:
    """Both tendons' ramps 18 % steeper, their edges moved by ``edge_move_deg``."""
    pos, neg = learned_knob(options)
    for _ in range(4):
        pos.update(ramp_with_edge(EDGE_DEG + edge_move_deg, 1.18 * SLOPE), EDGE_DEG, neg)
        neg.update(ramp_with_edge(EDGE_DEG + edge_move_deg, 1.18 * SLOPE), EDGE_DEG, pos)
    return pos


def test_steeper_ramps_without_a_followed_change_leave_the_backlash_gain() -> None:
    pos = steeper_knob(EstimatorOptions(), 0.0)
    assert pos.applied_deg == 0.0 and pos.gain_ratio == 1.0


def test_steeper_ramps_with_a_followed_widening_scale_the_backlash_gain() -> None:
    pos = steeper_knob(EstimatorOptions(), 3.0)
    assert pos.applied_deg == pytest.approx(3.0, abs=0.05)
    assert pos.gain_ratio == pytest.approx(1.18, abs=0.01)


def test_without_the_rule_steeper_ramps_alone_scale_the_backlash_gain() -> None:
    pos = steeper_knob(EstimatorOptions(gain_after_follow=False), 0.0)
    assert pos.gain_ratio == pytest.approx(1.18, abs=0.01)
