"""A tip that creeps while the handle's play opens: the rope the drum paid out is wound back
before the far flanks meet, so the play closes later where the tip crept more. A rigid play
closes at one travel after every reversal; where a knob's play ends move over its grid, its B
is flagged: a one-line warning naming the knob, and B's reported half-width reaching back to
the line rule's end."""

from __future__ import annotations

import dataclasses

import pytest
from support.handle_play import (
    LINE_END_DEG,
    OTHER_DEG,
    falling_sweep,
    play_offset,
    reversing_sweep,
)

from tsmd.calibration.assemble import GridPoint, QualityReport
from tsmd.calibration.play_creep import (
    CREEP_SPREAD_DEG,
    SIDE_GAP_DEG,
    check_play_creep,
    creeping_sides,
    play_creep,
    reread_at_swing_end,
)
from tsmd.calibration.reading_offset import corrected
from tsmd.calibration.resweep import point_estimates
from tsmd.calibration.sweep_result import SweepResult

SHEET_PLAY_DEG = -10.0


def knob_points(play_ends_deg: tuple[float, ...], knob: int = 0,
                play_deg: float = SHEET_PLAY_DEG) -> list[GridPoint]:
    """One sweep per other-knob angle, read through the sheet's offset (the play-end reading
    where the sheet announces a play)."""
    offset = play_offset(play_deg)
    return [GridPoint(knob, other, corrected(falling_sweep(end, seed), offset, other))
            for seed, (other, end) in enumerate(zip(OTHER_DEG, play_ends_deg, strict=True))]


RIGID = (15.0, 15.2, 14.9)
CREEPING = (15.0, 17.5, 19.0)
BOTH_SIDES = ("backlash_pos_deg", "backlash_neg_deg")


def two_sided_points(ends_deg: tuple[tuple[float, float], ...]) -> list[GridPoint]:
    """One sweep per other-knob angle with both sides' play ends (B_pos, B_neg), read through
    a sheet announcing the play on both."""
    offset = play_offset(SHEET_PLAY_DEG, BOTH_SIDES)
    return [GridPoint(0, other, corrected(reversing_sweep(pos, neg, seed), offset, other))
            for seed, (other, (pos, neg)) in enumerate(zip(OTHER_DEG, ends_deg, strict=True))]


# A mild creep delaying one side at one grid point by 1.1 deg: under the spread limit.
ONE_SIDE_LATE = ((15.0, 15.1), (15.0, 15.0), (15.0, 16.1))


def test_a_rigid_play_closes_at_one_travel_over_the_grid() -> None:
    creep = play_creep(knob_points(RIGID), 0)
    assert creep is not None
    assert creep.spread_deg < CREEP_SPREAD_DEG


def test_a_play_end_moving_over_the_grid_shows_its_spread() -> None:
    creep = play_creep(knob_points(CREEPING), 0)
    assert creep is not None
    assert creep.spread_deg == pytest.approx(4.0, abs=0.4)


def test_a_rigid_play_gives_no_warning_and_keeps_the_half_widths() -> None:
    points = knob_points(RIGID)
    before = [p.result.unit_u95_deg("backlash_pos_deg") for p in points]
    report = QualityReport()
    check_play_creep(points, report)
    assert report.warnings == []
    assert [p.result.unit_u95_deg("backlash_pos_deg") for p in points] == before


def test_a_creeping_knob_is_warned_about_in_one_line_naming_it() -> None:
    report = QualityReport()
    check_play_creep(knob_points(CREEPING, knob=1), report)
    assert len(report.warnings) == 1
    warning = report.warnings[0]
    assert "\n" not in warning
    assert warning.startswith("phi2: backlash unsure")
    assert "creep" in warning and "play" in warning


def test_a_creeping_knobs_half_width_reaches_back_to_the_line_end() -> None:
    points = knob_points(CREEPING)
    check_play_creep(points, QualityReport())
    for p, e in zip(points, point_estimates(points), strict=True):
        # the part no sweep narrows (one half-cycle: the gate's own part is unbounded here)
        assert e["backlash_pos_deg"].value - p.result.unit_u95_deg("backlash_pos_deg") \
            <= LINE_END_DEG - 1.0


def test_a_creeping_knobs_late_sides_are_read_at_the_swings_end() -> None:
    # 15.0 / 17.5 / 19.0: the play closes 2.5 and 4 deg after the knob's earliest close at the
    # other knob's 0 and +90, where the tip crept before it; its B is the swing's end there.
    points = knob_points(CREEPING)
    check_play_creep(points, QualityReport())
    values = [p.result.estimate("backlash_pos_deg") for p in points]
    assert values[0] == pytest.approx(15.0, abs=0.5)
    assert values[1] == pytest.approx(LINE_END_DEG, abs=0.01)
    assert values[2] == pytest.approx(LINE_END_DEG, abs=0.01)


def test_a_creeping_knobs_sides_closing_with_the_earliest_keep_the_plays_end() -> None:
    # One side late by 1.1 deg at +90: only that side is re-read.
    points = two_sided_points(ONE_SIDE_LATE)
    before = [dict(p.result.values) for p in points]
    check_play_creep(points, QualityReport())
    assert points[2].result.estimate("backlash_neg_deg") == pytest.approx(LINE_END_DEG,
                                                                          abs=0.01)
    assert points[2].result.values["backlash_pos_deg"] == before[2]["backlash_pos_deg"]
    assert [p.result.values for p in points[:2]] == before[:2]


def test_the_compensators_frame_keeps_the_plays_end_where_b_is_re_read() -> None:
    points = knob_points(CREEPING)
    values = [p.result.values for p in points]
    check_play_creep(points, QualityReport())
    assert [p.in_model_frame().result.values for p in points] == values


def test_a_rigid_knobs_values_are_not_re_read() -> None:
    points = two_sided_points(((15.0, 15.2), (14.9, 15.0), (15.2, 15.1)))
    values = [p.result.values for p in points]
    check_play_creep(points, QualityReport())
    assert [p.result.values for p in points] == values


def test_a_re_read_b_keeps_its_half_cycles_scatter() -> None:
    late = SweepResult(None, (), {"backlash_pos_deg": (18.0, 19.0, 20.0)})  # type: ignore[arg-type]
    moved = reread_at_swing_end(late, {"backlash_pos_deg"}, 3.0)
    assert moved.values["backlash_pos_deg"] == pytest.approx((2.0, 3.0, 4.0))


def test_a_side_whose_play_never_closed_in_the_window_is_creeping() -> None:
    # 30 deg after the reversal: beyond the sheet's window, no step found (the creep's rope).
    assert creeping_sides(knob_points((15.0, 30.0, 30.0)), 0) == {
        (0.0, "backlash_pos_deg"), (90.0, "backlash_pos_deg")}


def test_a_play_closing_beyond_the_sheets_window_in_most_half_cycles_is_flagged() -> None:
    # 30 deg after the reversal: past the line end plus twice the sheet's 10 deg play.
    points = knob_points((15.0, 30.0, 30.0))
    creep = play_creep(points, 0)
    assert creep is not None and creep.missing == 2
    report = QualityReport()
    check_play_creep(points, report)
    assert len(report.warnings) == 1
    assert "no step where the play should close in 2 of 3 half-cycles" in report.warnings[0]


def test_a_backlash_not_read_at_a_plays_end_is_never_flagged() -> None:
    # The line rule's values (every other product: no play end read), however they spread.
    points = [GridPoint(0, other, SweepResult(falling_sweep(15.0, 0).data, (),
                                              {"backlash_pos_deg": (value,)}))
              for other, value in zip(OTHER_DEG, (5.0, 9.0, 13.0), strict=True)]
    report = QualityReport()
    check_play_creep(points, report)
    assert play_creep(points, 0) is None
    assert report.warnings == []


def test_a_sheet_announcing_no_play_reads_no_play_end() -> None:
    points = knob_points(CREEPING, play_deg=-1.5)
    assert all(not p.result.own_offset_deg for p in points)


def test_a_resweeps_play_ends_are_pooled_with_the_first_sweeps() -> None:
    first, again = knob_points((15.0, 19.0, 15.0))[:2]
    pooled = first.result.merged(again.result)
    assert len(pooled.play_ends_deg["backlash_pos_deg"]) == 2
    assert pooled.play_ends_deg["backlash_pos_deg"][1] == pytest.approx(19.0, abs=0.3)


def test_one_half_cycles_late_line_end_does_not_narrow_the_half_width() -> None:
    # The swing's end is the drive train's: the knob's earliest line end counts everywhere.
    points = knob_points(CREEPING)
    late = points[2].result
    half = dataclasses.replace(late.half_cycles[0], backlash_deg=8.0)
    points[2] = dataclasses.replace(points[2], result=dataclasses.replace(late,
                                                                           half_cycles=(half,)))
    check_play_creep(points, QualityReport())
    b = points[2].result
    assert b.estimate("backlash_pos_deg") - b.unit_u95_deg("backlash_pos_deg") \
        <= LINE_END_DEG - 1.0


def test_one_early_play_end_does_not_flag_a_rigid_play() -> None:
    # A play not yet fully open at a sweep's first reversal closes early once; a rigid play
    # never closes later than its swing and clearance, and only a creep delays it.
    points = knob_points(RIGID)
    first = points[0].result
    points[0] = dataclasses.replace(points[0], result=dataclasses.replace(
        first, play_ends_deg={"backlash_pos_deg": (11.0, 15.0)}))
    report = QualityReport()
    check_play_creep(points, report)
    assert report.warnings == []


def test_both_sides_of_a_rigid_play_close_together() -> None:
    creep = play_creep(two_sided_points(((15.0, 15.2), (14.9, 15.0), (15.2, 15.1))), 0)
    assert creep is not None
    assert creep.side_gap_deg < SIDE_GAP_DEG
    assert creep.rigid()


def test_a_play_closing_later_on_one_side_shows_the_gap() -> None:
    creep = play_creep(two_sided_points(ONE_SIDE_LATE), 0)
    assert creep is not None
    assert creep.side_gap_deg == pytest.approx(1.1, abs=0.3)
    assert creep.spread_deg < CREEP_SPREAD_DEG


def test_a_mild_creep_on_one_side_is_flagged_though_the_spread_is_small() -> None:
    points = two_sided_points(ONE_SIDE_LATE)
    report = QualityReport()
    check_play_creep(points, report)
    assert len(report.warnings) == 1
    assert "two sides close" in report.warnings[0]
    for p, e in zip(points, point_estimates(points), strict=True):
        for name in BOTH_SIDES:
            assert e[name].value - p.result.unit_u95_deg(name) <= LINE_END_DEG - 1.0


def test_a_rigid_two_sided_play_gives_no_warning() -> None:
    report = QualityReport()
    check_play_creep(two_sided_points(((15.0, 15.2), (14.9, 15.0), (15.2, 15.1))), report)
    assert report.warnings == []
    assert report.figures["phi1_play_end_side_gap_deg"] < SIDE_GAP_DEG


def test_a_stick_ends_offset_is_no_play_and_reads_no_play_end() -> None:
    # pronyring: B read where the stick phase ends, its sheet offset -5 deg; no handle play.
    sweep = falling_sweep(None, 0)
    read = corrected(sweep, play_offset(-5.0), 0.0, read_play=False)
    assert read.play_ends_deg == {}
    assert read.values["backlash_pos_deg"] == pytest.approx((LINE_END_DEG + 5.0,))


def test_a_stick_end_knob_gives_no_creep_warning() -> None:
    points = [GridPoint(0, other, corrected(falling_sweep(None, seed), play_offset(-5.0), other,
                                            read_play=False))
              for seed, other in enumerate(OTHER_DEG)]
    report = QualityReport()
    check_play_creep(points, report)
    assert report.warnings == []
    # the play-end search on the same sweeps finds no step and flags the knob
    searched = [GridPoint(0, other, corrected(falling_sweep(None, seed), play_offset(-5.0),
                                              other))
                for seed, other in enumerate(OTHER_DEG)]
    check_play_creep(searched, report)
    assert len(report.warnings) == 1
