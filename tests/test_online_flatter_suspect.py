"""A widening that both slopes read outward beyond the gate, on a ramp flatter than the slope
in use, is a suspect at its own slope's crossing (EstimatorOptions.flatter_suspect_reads_own):
a friction that fell flattens the loaded ramp about its foot, so the slope in use puts the foot
too far out (notchclutch's liner soaking after insertion, a slack read 1-2 deg beyond its
size). A steeper ramp's widening is read as before."""

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
SHIFT_DEG = 3.5
"""A slack's move of the edge: beyond the gate with either slope."""


def ramp(shift_deg: float = 0.0, slope_ratio: float = 1.0) -> LoadedRamp:
    """A ramp whose foot (its own slope's crossing of the level) moved ``shift_deg`` outward,
    its slope ``slope_ratio`` x the reference's."""
    return LoadedRamp(0, 1, EDGE_DEG + shift_deg + WINDOW_DEG,
                      LEVEL_A + SLOPE * slope_ratio * WINDOW_DEG, SLOPE * slope_ratio,
                      0.0, 0.0, 200, 0.003)


def changed_edge(options: EstimatorOptions, slope_ratio: float) -> EdgeTracker:
    """A knob's positive edge: references learned on the profile's ramp, then one ramp whose
    foot moved ``SHIFT_DEG`` outward at ``slope_ratio`` x the reference's slope."""
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp(), EDGE_DEG, neg)
        neg.update(ramp(), EDGE_DEG, pos)
    pos.update(ramp(SHIFT_DEG, slope_ratio), EDGE_DEG, neg)
    return pos


def slope_in_use_reading(slope_ratio: float) -> float:
    """The crossing of the line through the window's centre with the reference's slope."""
    return SHIFT_DEG + WINDOW_DEG * (1.0 - slope_ratio)


def test_a_flatter_ramps_widening_is_a_suspect_at_its_own_slopes_crossing() -> None:
    edge = changed_edge(EstimatorOptions(), 0.9)
    assert edge.suspects == [pytest.approx(SHIFT_DEG, abs=0.01)]
    assert edge.status()["flatter_own_ramps"] == 1


def test_without_the_rule_it_is_a_suspect_at_the_slope_in_uses_crossing() -> None:
    edge = changed_edge(EstimatorOptions(flatter_suspect_reads_own=False), 0.9)
    assert edge.suspects == [pytest.approx(slope_in_use_reading(0.9), abs=0.01)]
    assert slope_in_use_reading(0.9) - SHIFT_DEG > 1.0


def test_a_steeper_ramps_widening_is_read_as_without_the_rule() -> None:
    on = changed_edge(EstimatorOptions(), 1.1)
    off = changed_edge(EstimatorOptions(flatter_suspect_reads_own=False), 1.1)
    assert on.suspects == off.suspects
    assert on.status()["flatter_own_ramps"] == 0

