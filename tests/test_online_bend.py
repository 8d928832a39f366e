"""The product's bend relation: measured on one unit's calibrations, applied with the edges."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
from test_online_estimator import SLOPE, _both_edges_18_percent_steeper, learned, ramp_with_edge

from tsmd.compensation import build_compensator
from tsmd.online import OnlineError
from tsmd.online.bend import (
    BendRelation,
    bend_targets,
    measure_bend_relation,
    release_line_deg,
    tendon_values,
    zero_load_move_deg,
)
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.profile import load_profile

PROFILE = Path(__file__).resolve().parents[1] / "profiles" / "example-sim.yaml"


def fake_profile(edge_deg: float, zero_load_deg: float, gain: float) -> Any:
    """A profile whose four tendons have the given (outward) edge, x0 and beta, other knob 0."""
    tp = SimpleNamespace(other_knob_deg=(-40.0, 0.0, 40.0),
                         dead_zone_pos_deg=(0.0, edge_deg, 0.0),
                         dead_zone_neg_deg=(0.0, -edge_deg, 0.0),
                         zero_load_pos_deg=(0.0, zero_load_deg, 0.0),
                         zero_load_neg_deg=(0.0, -zero_load_deg, 0.0),
                         backlash_gain_pos=(0.0, gain, 0.0), backlash_gain_neg=(0.0, gain, 0.0))
    return SimpleNamespace(knobs=(SimpleNamespace(tension_play=tp),) * 2)


def bent_by(release_move_deg: float, edge_move_deg: float, gain_ratio: float) -> Any:
    """The straight fake (edge 20, x0 5, beta 0.3) bent: x0 placed for the release line's move."""
    x0 = 5.0 + zero_load_move_deg(20.0, 5.0, 0.3, edge_move_deg, release_move_deg, gain_ratio)
    return fake_profile(20.0 + edge_move_deg, x0, 0.3 * gain_ratio)


def test_the_release_line_meets_the_plateau_a_backlash_inside_the_edge() -> None:
    assert release_line_deg(20.0, 5.0, 0.3) == pytest.approx(20.0 - 0.3 * 15.0)


def test_a_slack_change_moves_the_zero_load_point_with_the_edge() -> None:
    assert zero_load_move_deg(20.0, 5.0, 0.3, 3.0, 3.0, 1.0) == pytest.approx(3.0)


def test_the_zero_load_point_is_placed_for_the_release_lines_move() -> None:
    bent = tendon_values(bent_by(3.5, 3.0, 1.2), 0)[0]
    assert release_line_deg(*bent) - release_line_deg(20.0, 5.0, 0.3) == pytest.approx(3.5)


def test_the_relation_is_read_from_straight_and_bent_calibrations() -> None:
    relation = measure_bend_relation(fake_profile(20.0, 5.0, 0.3),
                                     [bent_by(3.5, 3.0, 1.21), bent_by(7.0, 6.0, 1.42)])
    assert relation.release_per_edge == pytest.approx(3.5 / 3.0)
    assert relation.gain_per_release_deg == pytest.approx(0.06)


def test_bends_that_moved_no_edge_give_no_relation_in_one_line() -> None:
    with pytest.raises(OnlineError, match="no bend moved an edge"):
        measure_bend_relation(fake_profile(20.0, 5.0, 0.3), [bent_by(0.1, 0.1, 1.0)])


def test_an_implausible_relation_is_refused() -> None:
    with pytest.raises(OnlineError, match="implausible bend relation"):
        BendRelation(release_per_edge=-1.0, gain_per_release_deg=0.06)


def test_a_friction_change_on_both_edges_is_a_bend() -> None:
    pos, _ = _both_edges_18_percent_steeper(EstimatorOptions())
    assert pos.bend_weight == 1.0


def test_an_edge_move_with_unchanged_slopes_is_no_bend() -> None:
    pos, neg = learned(), learned()
    for _ in range(6):
        pos.update(ramp_with_edge(23.0, slope=SLOPE), 20.0, neg)
        neg.update(ramp_with_edge(23.0, slope=SLOPE), 20.0, pos)
    assert pos.applied_deg == pytest.approx(3.0, abs=0.05)
    assert pos.bend_weight == 0.0


def _targets(weight: float, feature: str = "crossing") -> tuple[Any, Any, Any]:
    """Bend targets for every edge moved 3 deg with bend share ``weight``, placed by
    ``feature``, on the example profile's knobs, with (r, c) = (1.2, 0.06); and those knobs."""
    knobs = build_compensator(load_profile(PROFILE), "ours", 0.004).knobs
    trackers = {(k, s): SimpleNamespace(applied_deg=3.0, bend_weight=weight, gain_ratio=1.5,
                                        zero_load_deg=2.5, last_feature=feature,
                                        options=EstimatorOptions())
                for k in (0, 1) for s in (1, -1)}
    zero, gain = bend_targets(BendRelation(1.2, 0.06), trackers, knobs)
    return zero, gain, knobs


def test_a_bend_moves_the_release_line_and_beta_by_the_relation() -> None:
    zero, gain, knobs = _targets(1.0)
    assert gain[0][0] == pytest.approx(1.0 + 0.06 * 3.6)
    values = knobs[0].field.at(0.0)
    d, x0, b = (float(values[knobs[0].field.column(n)]) for n in (
        "dead_zone_pos_deg", "zero_load_pos_deg", "backlash_gain_pos"))
    moved = release_line_deg(d + 3.0, x0 + zero[0][0], b * gain[0][0])
    assert moved - release_line_deg(d, x0, b) == pytest.approx(3.6)


def test_a_change_that_is_no_bend_moves_the_zero_load_point_with_the_edge() -> None:
    zero, gain, _ = _targets(0.0)
    assert [z for pair in zero for z in pair] == pytest.approx([3.0] * 4)
    assert gain == ((1.0, 1.0), (1.0, 1.0))


def test_an_edge_the_knee_placed_keeps_its_trackers_zero_load_and_gain() -> None:
    zero, gain, _ = _targets(1.0, feature="knee")
    assert zero == ((2.5, 2.5), (2.5, 2.5)) and gain == ((1.5, 1.5), (1.5, 1.5))
