"""The family bench says how often the reported half-widths cover the tip's truth."""

from __future__ import annotations

import numpy as np

from tsmd.bench.calibration_family import CatheterRun, family_table
from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import SweepResult
from tsmd.tracked_calibration import ProtocolRun, coverage_against, score


def _point(values: dict[str, tuple[float, ...]]) -> GridPoint:
    t = np.arange(10) * 0.01
    data = Conditioned(t, t, t, t, t, 100.0, 0.001, 0.0005, ())
    return GridPoint(0, 0.0, SweepResult(data, (), values))


def test_a_value_is_covered_only_where_its_truth_lies_within_the_reported_half_width() -> None:
    # two half-cycles 1 deg apart: a half-width of several degrees around 20.5
    point = _point({"backlash_pos_deg": (20.0, 21.0), "backlash_neg_deg": (20.0, 21.0)})
    truth = {(0, 0.0): {"backlash_pos_deg": 20.6, "backlash_neg_deg": 60.0}}
    cover = coverage_against([point], truth)
    assert cover["backlash"] == (1, 2)
    assert cover["dead-zone edge"] == (0, 0)


def test_a_grid_point_without_truth_is_not_scored() -> None:
    point = _point({"backlash_pos_deg": (20.0, 21.0)})
    assert coverage_against([point], {(1, 0.0): {"backlash_pos_deg": 20.5}})["backlash"] == (0, 0)


def test_the_family_table_says_the_coverage_and_the_worst_covered_unit() -> None:
    truth = {(k, o): {"backlash_pos_deg": 25.0, "backlash_neg_deg": 24.0}
             for k in (0, 1) for o in (-90.0, 0.0, 90.0)}
    runs = []
    for unit, offset_deg in ((1, 0.0), (2, 5.0)):
        values = {n: (v + offset_deg, v + offset_deg) for n, v in truth[(0, 0.0)].items()}
        points = [GridPoint(k, o, SweepResult(None, (), values))  # type: ignore[arg-type]
                  for k, o in truth]
        run = ProtocolRun("fast", True, "", points, [], 200.0, 10.0, 3.0, 1000)
        score(run, truth)
        runs.append(CatheterRun("p", unit, 0, {"fast": run}, 100.0))
    table = family_table(runs, "fast")
    assert "covers the tip's threshold truth" in table
    assert "backlash 12/24 (50%; worst unit 2 seed 0 0/12)" in table
