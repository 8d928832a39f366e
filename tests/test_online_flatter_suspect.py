"""With EstimatorOptions.flatter_suspect_reads_own (off by default, session 25), a widening that
both slopes read outward beyond the gate, on a ramp flatter than the slope in use while the
knob's slopes fell (a friction that fell on both tendons), is a suspect at its own slope's
crossing: such a fall flattens the loaded ramp about its foot, so the slope in use puts the
foot too far out (notchclutch's liner soaking after insertion, a slack read 1-2 deg beyond its
size). Otherwise, and with the option off, the widening is read as before."""

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
FELL = 0.85
"""Both tendons' ramps after the friction fell, x the reference's slope."""
LAST = 0.8
"""The changed ramp, flatter than the slope in use."""
ON = EstimatorOptions(flatter_suspect_reads_own=True)
OFF = EstimatorOptions(flatter_suspect_reads_own=False)


def ramp(shift_deg: float = 0.0, slope_ratio: float = 1.0) -> LoadedRamp:
    """A ramp whose foot (its own slope's crossing of the level) moved ``shift_deg`` outward,
    its slope ``slope_ratio`` x the reference's."""
    return LoadedRamp(0, 1, EDGE_DEG + shift_deg + WINDOW_DEG,
                      LEVEL_A + SLOPE * slope_ratio * WINDOW_DEG, SLOPE * slope_ratio,
                      0.0, 0.0, 200, 0.003)


def changed_edge(options: EstimatorOptions, fell: bool) -> EdgeTracker:
    """A knob's positive edge: references learned on the profile's ramp, then (``fell``) three
    ramps of each tendon ``FELL`` x as steep with their feet in place, then one ramp whose foot
    moved ``SHIFT_DEG`` outward at ``LAST`` x the reference's slope."""
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp(), EDGE_DEG, neg)
        neg.update(ramp(), EDGE_DEG, pos)
    for _ in range(3 if fell else 0):
        pos.update(ramp(0.0, FELL), EDGE_DEG, neg)
        neg.update(ramp(0.0, FELL), EDGE_DEG, pos)
    pos.update(ramp(SHIFT_DEG, LAST), EDGE_DEG, neg)
    return pos


def test_after_the_knobs_slopes_fell_a_flatter_ramps_widening_reads_at_its_own_slope() -> None:
    edge = changed_edge(ON, fell=True)
    assert edge.knob_change < -ON.slope_in_use_tolerance
    assert edge.suspects == [pytest.approx(SHIFT_DEG, abs=0.01)]
    assert edge.status()["flatter_own_ramps"] == 1


def test_with_the_option_off_it_reads_at_the_slope_in_use_further_out() -> None:
    edge = changed_edge(OFF, fell=True)
    assert len(edge.suspects) == 1
    assert edge.suspects[0] > SHIFT_DEG + 0.5
    assert edge.status()["flatter_own_ramps"] == 0


def test_a_flatter_ramp_while_the_knobs_slopes_stayed_reads_as_with_the_option_off() -> None:
    on, off = changed_edge(ON, fell=False), changed_edge(OFF, fell=False)
    assert on.suspects == off.suspects
    assert on.status()["flatter_own_ramps"] == 0


def test_the_option_is_off_by_default() -> None:
    assert EstimatorOptions().flatter_suspect_reads_own is False
