"""A crossing beyond the gate reads at the share of the way between the slope in use's crossing
and the ramp's own that the edge's crossings took before any change was followed
(EstimatorOptions.suspect_reads_learned_share; tsmd/online/slope_share.py): twistshaft 2's
phi1 positive ramps ran 1.05 x its reference before and after a +0.5 mm slack, landed on the
edge with their own slope before it, and the follow read 0.9 deg short with the slope in use."""

from __future__ import annotations

import pytest

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp
from tsmd.online.slope_share import SlopeShare

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
STEEPER = 1.06
"""This tendon's ramps after the reference: within the shrink of the slope in use."""
WINDOW_OUT_DEG = 20.0
"""The window centre this far outward of the ramp's own crossing: a 6 % steeper ramp's
crossing with the reference slope lies 1.2 deg inward of its own."""
SLACK_DEG = 4.0


def ramp(own_crossing_deg: float, slope: float, side: int = 1) -> LoadedRamp:
    """A ramp of ``slope`` whose own line crosses LEVEL_A ``own_crossing_deg`` outward."""
    return LoadedRamp(0, side, own_crossing_deg + WINDOW_OUT_DEG,
                      LEVEL_A + slope * WINDOW_OUT_DEG, slope, 0.0, 0.0, 200, 0.003)


def slack_on_a_steeper_tendon(options: EstimatorOptions, lands_with_own: bool
                              ) -> EdgeTracker:
    """The positive edge: reference ramps, three steeper ramps on the edge (landing there with
    their own slope, or with the reference's), then a slack read by both edges."""
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp(EDGE_DEG, SLOPE), EDGE_DEG, neg)
        neg.update(ramp(EDGE_DEG, SLOPE, -1), EDGE_DEG, pos)
    own_at = 0.0 if lands_with_own else WINDOW_OUT_DEG * (STEEPER - 1.0)
    for _ in range(3):
        pos.update(ramp(EDGE_DEG + own_at, STEEPER * SLOPE), EDGE_DEG, neg)
    assert pos.applied_deg == 0.0
    neg.update(ramp(EDGE_DEG + SLACK_DEG, SLOPE, -1), EDGE_DEG, pos)
    for _ in range(2):
        pos.update(ramp(EDGE_DEG + own_at + SLACK_DEG, STEEPER * SLOPE), EDGE_DEG, neg)
    return pos


def test_a_slack_on_a_tendon_that_landed_with_its_own_slope_reads_with_its_own() -> None:
    pos = slack_on_a_steeper_tendon(EstimatorOptions(suspect_reads_learned_share=True), True)
    assert pos.share.share == pytest.approx(1.0)
    assert pos.applied_deg == pytest.approx(SLACK_DEG, abs=0.01)


def test_without_the_rule_the_slack_reads_short_with_the_slope_in_use() -> None:
    pos = slack_on_a_steeper_tendon(EstimatorOptions(suspect_reads_learned_share=False), True)
    assert pos.applied_deg == pytest.approx(SLACK_DEG - 1.2, abs=0.05)


def test_a_tendon_that_landed_with_the_slope_in_use_keeps_it() -> None:
    pos = slack_on_a_steeper_tendon(EstimatorOptions(suspect_reads_learned_share=True), False)
    assert pos.share.share == pytest.approx(0.0)
    assert pos.applied_deg == pytest.approx(SLACK_DEG + WINDOW_OUT_DEG * (STEEPER - 1.0) - 1.2,
                                            abs=0.05)


def test_an_unlearned_share_reads_the_slope_in_use() -> None:
    share = SlopeShare()
    share.teach(-1.0, 0.0, 0.0)
    assert share.share is None
    assert share.read(3.0, 4.0) == 3.0


def test_the_share_is_the_least_squares_fraction_between_the_two_crossings() -> None:
    share = SlopeShare()
    share.teach(-1.0, 1.0, 0.0)  # half way
    share.teach(-2.0, 2.0, 0.0)
    assert share.share == pytest.approx(0.5)
    assert share.read(3.0, 5.0) == pytest.approx(4.0)


def test_crossings_that_scatter_more_than_the_slopes_part_them_teach_no_share() -> None:
    # coilpipe 1 phi1 before a slack: two crossings 0.3-0.6 deg apart, both ~1 deg out
    share = SlopeShare()
    share.teach(1.05, 0.78, 0.0)
    share.teach(0.98, 0.43, 0.0)
    assert share.share is None
    assert share.read(2.78, 1.25) == 2.78


def test_a_share_well_beyond_the_two_slopes_counts_as_none() -> None:
    beyond = SlopeShare()
    for _ in range(2):
        beyond.teach(0.0, 1.0, 3.0)  # landed 3 x beyond the own slope's crossing
    assert beyond.share is None


def test_the_status_reports_the_learned_share_and_its_readings() -> None:
    pos = slack_on_a_steeper_tendon(EstimatorOptions(suspect_reads_learned_share=True), True)
    status = pos.status()
    assert status["learned_share"] == 1.0
    assert status["share_read_ramps"] == 2
