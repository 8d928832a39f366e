"""A crossing within the gate of a ramp whose slope differs from the slope in use reads towards
the ramp's own slope's crossing (EstimatorOptions.within_gate_reads_own): a catheter softening
or stiffening in use does not creep the edge; a widening beyond the gate is read as before."""

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
SOFTER = 0.95
"""Ramps this much flatter: within the slope in use's tolerance, so that stays the reference's."""


def ramp(shift_deg: float = 0.0, slope_ratio: float = 1.0) -> LoadedRamp:
    """A ramp whose edge moved ``shift_deg`` outward and whose slope turned by ``slope_ratio``
    about that edge (the current at the edge unchanged, as when the catheter softens)."""
    return LoadedRamp(0, 1, EDGE_DEG + shift_deg + WINDOW_DEG,
                      LEVEL_A + SLOPE * slope_ratio * WINDOW_DEG, SLOPE * slope_ratio,
                      0.0, 0.0, 200, 0.003)


def run_knob(options: EstimatorOptions, shift_deg: float, slope_ratio: float = SOFTER,
             ramps: int = 8) -> tuple[EdgeTracker, EdgeTracker]:
    """Both edges of a knob: references learned on the profile's ramp, then ``ramps`` ramps
    per edge moved ``shift_deg`` and turned by ``slope_ratio`` about their edge."""
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp(), EDGE_DEG, neg)
        neg.update(ramp(), EDGE_DEG, pos)
    for _ in range(ramps):
        pos.update(ramp(shift_deg, slope_ratio), EDGE_DEG, neg)
        neg.update(ramp(shift_deg, slope_ratio), EDGE_DEG, pos)
    return pos, neg


def test_softer_ramps_within_the_gate_leave_the_edges_in_place() -> None:
    pos, neg = run_knob(EstimatorOptions(), 0.0)
    assert (pos.applied_deg, neg.applied_deg) == (0.0, 0.0)
    assert pos.status()["own_slope_ramps"] > 0


def test_without_the_rule_softer_ramps_creep_the_edges_outward() -> None:
    pos, neg = run_knob(EstimatorOptions(within_gate_reads_own=False), 0.0)
    creep = WINDOW_DEG * (1.0 - SOFTER)
    assert pos.applied_deg == pytest.approx(creep, abs=0.01)
    assert neg.applied_deg == pytest.approx(creep, abs=0.01)


def test_stiffer_ramps_within_the_gate_leave_the_edges_in_place() -> None:
    on, _ = run_knob(EstimatorOptions(), 0.0, 2.0 - SOFTER)
    off, _ = run_knob(EstimatorOptions(within_gate_reads_own=False), 0.0, 2.0 - SOFTER)
    assert on.applied_deg == 0.0
    assert off.applied_deg == pytest.approx(-WINDOW_DEG * (1.0 - SOFTER), abs=0.01)


def test_a_widening_beyond_the_gate_on_softer_ramps_is_followed_as_without_the_rule() -> None:
    on, _ = run_knob(EstimatorOptions(), 3.0)
    off, _ = run_knob(EstimatorOptions(within_gate_reads_own=False), 3.0)
    assert on.level_deg == off.level_deg > 1.5
    assert on.applied_deg == pytest.approx(off.applied_deg)
