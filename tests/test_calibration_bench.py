"""The family benchmark's bookkeeping: scoring against the tip's truth and the family table."""

from __future__ import annotations

import math

from tsmd.bench.calibration_family import CatheterRun, family_table
from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.sweep_result import PARAMETERS, SweepResult
from tsmd.tracked_calibration import ProtocolRun, score

GRID = (-90.0, -60.0, -30.0, 0.0, 30.0, 60.0, 90.0)
TRUE = {"dead_zone_pos_deg": 20.0, "dead_zone_neg_deg": -20.0, "backlash_pos_deg": 25.0,
        "backlash_neg_deg": 24.0}


def _run(offset_deg: float, accepted: bool = True) -> ProtocolRun:
    values = {n: (v + offset_deg, v + offset_deg) for n, v in TRUE.items()}
    points = [GridPoint(k, o, SweepResult(None, (), values))  # type: ignore[arg-type]
              for k in (0, 1) for o in (-90.0, 0.0, 90.0)]
    return ProtocolRun("fast", accepted, "" if accepted else "refused: test", points, [],
                       200.0, 10.0, 3.0, 1000)


def _truth() -> dict[tuple[int, float], dict[str, float]]:
    return {(k, o): dict(TRUE) for k in (0, 1) for o in GRID}


def test_a_profile_is_scored_on_the_56_values_of_the_papers_grid() -> None:
    run = _run(0.5)
    score(run, _truth())
    assert len(run.errors) == 2 * len(GRID) * len(PARAMETERS) == 56
    assert all(math.isclose(e, 0.5) for e in run.errors)
    assert run.within == 56


def test_the_table_names_the_worst_unit_and_every_refusal() -> None:
    good, bad = _run(0.2), _run(2.5, accepted=False)
    for r in (good, bad):
        score(r, _truth())
    table = family_table([CatheterRun("p", 1, 0, {"fast": good}, 100.0),
                          CatheterRun("p", 2, 0, {"fast": bad}, 100.0)], "fast")
    assert "accepted: 1 of 2 runs (50%)" in table
    assert "worst: unit 2 noise seed 0: 0/56 within 2 deg, max 2.50 deg" in table
    assert "refused: unit 2 seed 0: refused: test" in table


def test_the_table_scores_the_runs_against_the_line_truth_too() -> None:
    run = _run(0.0)
    lines_truth = {key: {n: v + 3.0 for n, v in vals.items()} for key, vals in _truth().items()}
    score(run, _truth(), lines_truth)
    table = family_table([CatheterRun("p", 1, 0, {"fast": run}, 100.0)], "fast")
    assert run.within == 56
    assert "line truth (corners of the paper's lines on the tip): 0 of 56 within 2 deg" in table
