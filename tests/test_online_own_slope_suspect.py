"""A crossing beyond the gate with the slope in use is a suspect only when the ramp's own slope
puts it beyond the gate too (EstimatorOptions.suspect_needs_own_slope): a ramp a few per cent
flatter than the slope in use reads ~15 deg x its slope's error outward with the slope in use
(planetwist 101 without a change), while a shift of the edge shows with either slope. Such a
reading still confirms a suspect the knob's other edge holds the same way (a slack's first
ramps)."""

from __future__ import annotations

import pytest

from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
WINDOW_DEG = 15.0
"""How far beyond the edge the ramp's window centre sits."""
FLATTER = 0.9
"""Within the tolerance that makes a ramp an odd slope (15 %), beyond the slope in use's (5 %)."""


def ramp(shift_deg: float = 0.0, slope_ratio: float = 1.0) -> LoadedRamp:
    """A ramp whose edge (its own slope's crossing) moved ``shift_deg`` outward, its slope
    ``slope_ratio`` x the reference's."""
    return LoadedRamp(0, 1, EDGE_DEG + shift_deg + WINDOW_DEG,
                      LEVEL_A + SLOPE * slope_ratio * WINDOW_DEG, SLOPE * slope_ratio,
                      0.0, 0.0, 200, 0.003)


def after_reference(options: EstimatorOptions, shift_deg: float,
                    partner_shift_deg: float | None = None) -> EdgeTracker:
    """The positive edge of a knob: the references learned on the profile's ramp, the negative
    edge then given one ramp moved ``partner_shift_deg`` (None: none), then the positive edge
    one ramp ``FLATTER`` x as steep whose own slope puts its edge ``shift_deg`` outward."""
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp(), EDGE_DEG, neg)
        neg.update(ramp(), EDGE_DEG, pos)
    if partner_shift_deg is not None:
        neg.update(ramp(partner_shift_deg), EDGE_DEG, pos)
    pos.update(ramp(shift_deg, FLATTER), EDGE_DEG, neg)
    return pos


def slope_in_use_reading(shift_deg: float) -> float:
    """Where the line through the window's centre with the reference's slope crosses the level."""
    return shift_deg + WINDOW_DEG * (1.0 - FLATTER)


def test_a_flatter_ramp_read_outward_only_with_the_slope_in_use_is_no_suspect() -> None:
    edge = after_reference(EstimatorOptions(), 0.5)
    assert edge.suspects == []
    assert edge.last_measurement_deg == pytest.approx(0.5, abs=0.01)
    assert edge.status()["own_slope_held_ramps"] == 1


def test_without_the_rule_the_same_ramp_is_a_suspect_beyond_the_gate() -> None:
    edge = after_reference(EstimatorOptions(suspect_needs_own_slope=False), 0.5)
    assert edge.suspects == [pytest.approx(slope_in_use_reading(0.5), abs=0.01)]
    assert slope_in_use_reading(0.5) > edge.options.gate_deg


def test_a_widening_both_slopes_read_beyond_the_gate_stays_a_suspect_at_the_slope_in_use() -> None:
    # without flatter_suspect_reads_own (session 25, round 2), which reads it at its own slope
    on = after_reference(EstimatorOptions(flatter_suspect_reads_own=False), 3.0)
    off = after_reference(EstimatorOptions(suspect_needs_own_slope=False,
                                           flatter_suspect_reads_own=False), 3.0)
    assert on.suspects == off.suspects == [pytest.approx(slope_in_use_reading(3.0), abs=0.01)]


def test_the_same_ramp_confirms_a_suspect_the_other_edge_holds_outward() -> None:
    edge = after_reference(EstimatorOptions(), 0.5, partner_shift_deg=3.0)
    assert edge.suspects == [pytest.approx(slope_in_use_reading(0.5), abs=0.01)]
    assert edge.status()["own_slope_held_ramps"] == 0


def test_an_inward_suspect_of_the_other_edge_does_not_confirm_an_outward_reading() -> None:
    edge = after_reference(EstimatorOptions(), 0.5, partner_shift_deg=-3.0)
    assert edge.suspects == []
