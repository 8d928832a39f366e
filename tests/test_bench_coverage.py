"""The family bench says how often the reported half-widths cover the tip's truth."""

from __future__ import annotations

import numpy as np

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import SweepResult
from tsmd.tracked_calibration import coverage_against


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
