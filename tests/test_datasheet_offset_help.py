"""A backlash reading offset is written only where it helps on the sheet's unit (session 22)."""

from __future__ import annotations

from tsmd.datasheet_offset_help import helpful_offset, offset_gain_deg
from tsmd.profile.reading_offset import OffsetGrid, ReadingOffset

STEADY = [-1.4, -1.5, -1.6, -1.5]
"""Half-cycles reading one B a steady 1.5 deg short."""
TWO_FEATURES = [0.2, -0.3, 0.1, 8.5, 0.0, 9.0]
"""Most half-cycles on the tip, two at another feature 9 deg late."""


def offset(mean: float, u95: float) -> ReadingOffset:
    grid = OffsetGrid((mean,), (u95,), (4,))
    return ReadingOffset((0.0,), (("dead_zone_pos_deg", grid), ("backlash_pos_deg", grid)))


def test_a_steady_shift_taken_out_lowers_the_error_by_about_itself() -> None:
    assert abs(offset_gain_deg(STEADY, -1.5) - 1.45) < 0.1


def test_a_steady_offset_is_written() -> None:
    kept = helpful_offset(offset(-1.5, 0.3), 0, {(0, 0.0): {"backlash_pos_deg": STEADY}})
    assert kept is not None and kept.grid("backlash_pos_deg").mean_deg == (-1.5,)


def test_a_mean_between_two_features_is_written_as_zero() -> None:
    kept = helpful_offset(offset(3.0, 1.8), 0, {(0, 0.0): {"backlash_pos_deg": TWO_FEATURES}})
    assert kept is not None
    grid = kept.grid("backlash_pos_deg")
    assert grid.mean_deg == (0.0,) and grid.u95_deg == (1.8,)


def test_a_steady_offset_is_written_however_wide_its_half_width() -> None:
    kept = helpful_offset(offset(-1.5, 1.6), 0, {(0, 0.0): {"backlash_pos_deg": STEADY}})
    assert kept is not None and kept.grid("backlash_pos_deg").mean_deg == (-1.5,)


def test_an_offset_without_its_readings_is_written_as_zero() -> None:
    kept = helpful_offset(offset(-1.5, 0.3), 0, {})
    assert kept is not None and kept.grid("backlash_pos_deg").mean_deg == (0.0,)


def test_the_dead_zone_offset_is_left_as_measured() -> None:
    kept = helpful_offset(offset(3.0, 1.8), 0, {(0, 0.0): {"dead_zone_pos_deg": TWO_FEATURES,
                                                           "backlash_pos_deg": TWO_FEATURES}})
    assert kept is not None and kept.grid("dead_zone_pos_deg").mean_deg == (3.0,)
