"""The reading offset in two frames (session 26, round 2): the reported D/B take every sure
offset however small; our compensator's fit reads the sweep with the offsets of 1 deg and more
only, the frame the data sheet's reference edges, knees and gains were read in."""

from __future__ import annotations

import pytest

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.reading_offset import (
    REPORT_MIN_OFFSET_DEG,
    corrected,
    offset_at,
    reference_edge_deg,
)
from tsmd.calibration.resweep import pooled
from tsmd.calibration.sweep_result import SweepResult
from tsmd.profile.reading_offset import OffsetGrid, ReadingOffset

GRID = (-90.0, 0.0, 90.0)
SURE_SUB_DEGREE = ReadingOffset(GRID, (
    ("dead_zone_pos_deg", OffsetGrid((-0.9, -0.9, -0.9), (0.6, 0.6, 0.6), (4, 4, 4))),))


def result(*edges: float) -> SweepResult:
    return SweepResult(None, (), {"dead_zone_pos_deg": edges})  # type: ignore[arg-type]


def test_the_reported_edge_takes_a_sure_sub_degree_offset() -> None:
    r = corrected(result(24.0, 24.2), SURE_SUB_DEGREE, 0.0, min_deg=REPORT_MIN_OFFSET_DEG)
    assert r.values["dead_zone_pos_deg"] == pytest.approx((24.9, 25.1))
    assert r.offset_u95_deg["dead_zone_pos_deg"] == pytest.approx(0.6)


def test_the_compensators_frame_leaves_a_sub_degree_offset_as_read() -> None:
    r = corrected(result(24.0, 24.2), SURE_SUB_DEGREE, 0.0)
    assert r.values["dead_zone_pos_deg"] == (24.0, 24.2)


def test_the_sheets_reference_edge_and_knee_stay_in_the_compensators_frame() -> None:
    assert reference_edge_deg(SURE_SUB_DEGREE, "dead_zone_pos_deg", 20.0) == 20.0
    assert offset_at(SURE_SUB_DEGREE, "dead_zone_pos_deg", 0.0) == (0.0, 0.0)
    assert offset_at(SURE_SUB_DEGREE, "dead_zone_pos_deg", 0.0,
                     REPORT_MIN_OFFSET_DEG)[0] == pytest.approx(-0.9)


def test_the_fit_reads_a_point_in_the_compensators_frame() -> None:
    point = GridPoint(0, 0.0, result(24.9), model_result=result(24.0))
    assert point.in_model_frame().result.values["dead_zone_pos_deg"] == (24.0,)
    assert point.result.values["dead_zone_pos_deg"] == (24.9,)
    plain = GridPoint(0, 0.0, result(24.0))
    assert plain.in_model_frame() is plain


def test_a_resweep_is_pooled_in_both_frames() -> None:
    first = GridPoint(0, 0.0, result(24.9), model_result=result(24.0))
    again = GridPoint(0, 0.0, result(25.1), model_result=result(24.2))
    both = pooled(first, again)
    assert both.result.values["dead_zone_pos_deg"] == (24.9, 25.1)
    assert both.in_model_frame().result.values["dead_zone_pos_deg"] == (24.0, 24.2)
