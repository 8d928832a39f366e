"""A change is followed only once both knobs show it (``other_knob_confirms``): a shape change
moves every tendon's edge, one knob's crossings wandering on their own (coilpipe) do not."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from support.online import profile_edges, rows

from tsmd.compensation import build_compensator
from tsmd.loop import ROW_COLUMNS
from tsmd.online import OnlineWorker
from tsmd.online.estimator import EdgeTracker
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.features import LoadedRamp
from tsmd.profile import load_profile

PROFILE = Path(__file__).resolve().parents[1] / "profiles" / "example-sim.yaml"
CONFIRMS = EstimatorOptions(other_knob_confirms=True)


@pytest.fixture(scope="module")
def profile() -> Any:
    return load_profile(PROFILE)


def run(profile: Any, options: EstimatorOptions, knobs_moved: tuple[int, ...],
        shift_deg: float, others_deg: float = 0.0) -> OnlineWorker:
    """200 s of both knobs; from 100 s on the edges of ``knobs_moved`` read ``shift_deg``
    further out, the other knob's ``others_deg``."""
    comp = build_compensator(profile, "ours", 0.004)
    worker = OnlineWorker(comp, 0.004, ROW_COLUMNS, estimator=options, drain_every=25)
    moved = profile_edges(comp.knobs, shift_deg, at_s=100.0)
    still = profile_edges(comp.knobs, others_deg, at_s=100.0)

    def edges(t: float, knob: int, other_deg: float) -> tuple[float, float]:
        return (moved if knob in knobs_moved else still)(t, knob, other_deg)

    for row in rows(200.0, edges):
        worker.observe(row, True)
    worker.drain()
    return worker


def test_behaviour_one_knob_reading_out_is_followed_without_the_rule(profile: Any) -> None:
    worker = run(profile, EstimatorOptions(other_knob_confirms=False), (0,), 3.0)
    assert min(worker.trackers[(0, s)].applied_deg for s in (1, -1)) > 2.0


def test_one_knob_reading_out_alone_is_not_followed_with_the_rule(profile: Any) -> None:
    worker = run(profile, CONFIRMS, (0,), 3.0)
    assert max(abs(tr.applied_deg) for tr in worker.trackers.values()) <= 0.5


def test_a_change_both_knobs_show_is_followed_on_both_with_the_rule(profile: Any) -> None:
    worker = run(profile, CONFIRMS, (0, 1), 4.0)
    assert all(tr.applied_deg == pytest.approx(4.0, abs=0.8) for tr in worker.trackers.values())


def test_the_other_knob_leaning_below_its_gate_confirms_a_change(profile: Any) -> None:
    worker = run(profile, CONFIRMS, (0,), 3.0, others_deg=1.0)
    assert min(worker.trackers[(0, s)].applied_deg for s in (1, -1)) > 2.0


def test_without_the_lean_a_change_below_the_other_knobs_gate_waits(profile: Any) -> None:
    worker = run(profile, EstimatorOptions(other_knob_confirms=True, other_knob_lean=0.0), (0,),
                 3.0, others_deg=1.0)
    assert max(abs(worker.trackers[(0, s)].applied_deg) for s in (1, -1)) <= 0.5


def test_the_other_knob_leaning_the_other_way_does_not_confirm(profile: Any) -> None:
    worker = run(profile, CONFIRMS, (0,), 3.0, others_deg=-1.0)
    assert max(abs(worker.trackers[(0, s)].applied_deg) for s in (1, -1)) <= 0.5


def _ramp(edge_deg: float) -> LoadedRamp:
    """A ramp of the positive edge crossing 0.05 A at ``edge_deg``."""
    return LoadedRamp(0, 1, edge_deg + 10.0, 0.08, 0.003, 0.0, 0.0, 200, 0.003)


def _tracker_never_confirmed() -> EdgeTracker:
    tracker = EdgeTracker(0, 1, CONFIRMS, other_knob_shows=lambda direction: False)
    for _ in range(CONFIRMS.baseline_ramps):
        tracker.update(_ramp(20.0), 20.0)
    return tracker


def test_a_first_change_the_other_knob_does_not_show_is_not_followed() -> None:
    tracker = _tracker_never_confirmed()
    for _ in range(3):
        tracker.update(_ramp(23.0), 20.0)
    assert tracker.applied_deg == 0.0


def test_after_a_followed_change_the_edge_refines_it_on_its_own_ramps() -> None:
    tracker = _tracker_never_confirmed()
    tracker.follow(4.5, "both knobs showed it")
    for _ in range(3):
        tracker.update(_ramp(23.0), 20.0)
    assert tracker.applied_deg == pytest.approx(3.0, abs=0.01)
