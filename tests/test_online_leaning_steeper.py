"""The first steeper ramps after a bend read with their own slope when the crossing leans outward
(EstimatorOptions.leaning_steeper_reads_own), and an edge that follows on its own suspects takes
the knob's other edge's agreeing suspect with it (tsmd.online.partner.holds_agreeing_suspect)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tsmd.compensation import build_compensator
from tsmd.loop import ROW_COLUMNS
from tsmd.online import OnlineWorker
from tsmd.online.apply import edges_at
from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp
from tsmd.profile import load_profile

EDGE_DEG = 20.0
LEVEL_A = 0.05
SLOPE = 0.003
WINDOW_DEG = 15.0
"""How far beyond the edge the ramp's window centre sits."""
BEND_DEG = 3.0
STEEPER = 1.12
"""A bend's first ramps: steeper than the slope in use's tolerance, within the odd-slope one."""
PROFILE = Path(__file__).resolve().parents[1] / "profiles" / "example-sim.yaml"


def ramp(edge_deg: float, slope_ratio: float = 1.0, side: int = 1,
         other_deg: float = 0.0) -> LoadedRamp:
    """A ramp of ``side`` whose crossing of LEVEL_A is ``edge_deg`` outward (steeper by
    ``slope_ratio`` about it)."""
    slope = SLOPE * slope_ratio
    return LoadedRamp(0, side, edge_deg + WINDOW_DEG, LEVEL_A + slope * WINDOW_DEG,
                      slope, other_deg, 0.0, 200, 0.003)


def learned_knob(options: EstimatorOptions) -> tuple[EdgeTracker, EdgeTracker]:
    pos, neg = EdgeTracker(0, 1, options), EdgeTracker(0, -1, options)
    for _ in range(options.baseline_ramps):
        pos.update(ramp(EDGE_DEG), EDGE_DEG, neg)
        neg.update(ramp(EDGE_DEG, side=-1), -EDGE_DEG, pos)
    return pos, neg


def bend_ramps(options: EstimatorOptions, edge_deg: float, ramps: int = 2
               ) -> tuple[EdgeTracker, EdgeTracker]:
    """``ramps`` ramps per edge, STEEPER about an edge ``edge_deg`` outward, taken in turn."""
    pos, neg = learned_knob(options)
    for _ in range(ramps):
        pos.update(ramp(EDGE_DEG + edge_deg, STEEPER), EDGE_DEG, neg)
        neg.update(ramp(EDGE_DEG + edge_deg, STEEPER, -1), -EDGE_DEG, pos)
    return pos, neg


def test_a_bends_first_steeper_ramps_are_followed_within_two_ramps_per_edge() -> None:
    # the first ramp of the first edge has no steeper partner ramp yet and reads in the gate;
    # the next ones read the bend's edge as suspects (then the slope in use has followed)
    pos, neg = bend_ramps(EstimatorOptions(), BEND_DEG)
    assert neg.level_deg == pytest.approx(BEND_DEG, abs=0.01)
    assert pos.suspects == [pytest.approx(BEND_DEG, abs=0.01)]
    assert (pos.n_leaning_steeper, neg.n_leaning_steeper) == (1, 1)


def test_without_the_rule_the_first_steeper_ramps_read_inside_the_gate() -> None:
    pos, neg = bend_ramps(EstimatorOptions(leaning_steeper_reads_own=False), BEND_DEG)
    assert (pos.level_deg, neg.level_deg) == (0.0, 0.0)
    assert pos.suspects == []


def test_steeper_ramps_whose_crossing_stays_in_place_measure_no_widening() -> None:
    # turned about the window's centre: the slope in use's crossing reads the edge where it
    # was, and the own slope's, beyond the gate, is the slope's scatter, not a bend
    turned_pos, turned_neg = learned_knob(EstimatorOptions())
    for tr, side, edge in ((turned_pos, 1, EDGE_DEG), (turned_neg, -1, -EDGE_DEG)):
        centre = EDGE_DEG + WINDOW_DEG
        tr.update(LoadedRamp(0, side, centre, LEVEL_A + SLOPE * WINDOW_DEG, SLOPE * STEEPER,
                             0.0, 0.0, 200, 0.003), edge, turned_neg if side > 0 else turned_pos)
    assert turned_pos.status()["leaning_steeper_ramps"] == 0
    assert turned_neg.suspects == turned_pos.suspects == []


def worker_ramp(worker: OnlineWorker, side: int, edge_move_deg: float) -> LoadedRamp:
    """A ramp of knob 0 whose edge lies ``edge_move_deg`` outward of the profile's."""
    d_pos, d_neg = edges_at(worker.base_knobs[0], 0.0)
    edge = d_pos if side > 0 else -d_neg
    return ramp(edge + edge_move_deg, side=side)


def test_an_edge_following_on_its_own_suspects_takes_the_partners_agreeing_suspect() -> None:
    comp = build_compensator(load_profile(PROFILE), "ours", 0.004)
    worker = OnlineWorker(comp, 0.004, ROW_COLUMNS)
    pos, neg = worker.trackers[(0, 1)], worker.trackers[(0, -1)]
    for _ in range(3):
        worker._ramp(pos, worker_ramp(worker, 1, 0.0))
        worker._ramp(neg, worker_ramp(worker, -1, 0.0))
    worker._ramp(neg, worker_ramp(worker, -1, 2.6))  # neg's first suspect ...
    worker._ramp(pos, worker_ramp(worker, 1, 0.0))  # ... older than pos's reading in place
    worker._ramp(pos, worker_ramp(worker, 1, 2.4))  # so pos's suspect finds no fresh partner
    assert (pos.level_deg, neg.level_deg) == (0.0, 0.0)
    worker._ramp(neg, worker_ramp(worker, -1, 2.9))  # neg follows on two of its own
    assert neg.level_deg == pytest.approx(2.75, abs=0.01)
    assert pos.level_deg == pytest.approx(2.4, abs=0.01)
