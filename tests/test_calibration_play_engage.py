"""A handle's play whose end the current shows: after the reversal the current rests at the
friction level while the knob crosses the play, and steps off it when the drum re-engages;
where the sheet's reading offset announces such a play, B ends at the step."""

from __future__ import annotations

import numpy as np
import pytest
from support.handle_play import (
    LINE_END_DEG,
    NOISE_A,
    falling_sweep,
    play_offset,
    release_y,
)

from tsmd.calibration.play_engage import (
    MIN_PLAY_DEG,
    TIP_MOVE_DEG,
    engage,
    engage_lag_deg,
    engage_travel_deg,
)
from tsmd.calibration.reading_offset import corrected
from tsmd.tip_truth import TIP_THRESHOLD_DEG


def test_the_backlash_ends_where_the_current_steps_off_the_plays_level() -> None:
    read = engage(falling_sweep(15.0), {"backlash_pos_deg": -10.0}, {"backlash_pos_deg": -10.0})
    values, own = read.values, read.own
    assert values["backlash_pos_deg"][0] == pytest.approx(15.0, abs=0.3)
    assert own["backlash_pos_deg"] == pytest.approx(LINE_END_DEG - 15.0, abs=0.3)


def test_a_unit_with_more_play_than_the_sheets_reads_its_own() -> None:
    values = engage(falling_sweep(18.0), {"backlash_pos_deg": -10.0},
                    {"backlash_pos_deg": -10.0}).values
    assert values["backlash_pos_deg"][0] == pytest.approx(18.0, abs=0.3)


def test_a_current_that_never_leaves_its_level_keeps_the_sheets_offset() -> None:
    read = engage(falling_sweep(None), {"backlash_pos_deg": -10.0}, {"backlash_pos_deg": -10.0})
    values, own = read.values, read.own
    assert values["backlash_pos_deg"] == pytest.approx((LINE_END_DEG + 10.0,))
    assert own == {}


def test_a_step_far_beyond_what_the_sheet_announces_is_not_taken() -> None:
    values = engage(falling_sweep(LINE_END_DEG + 25.0), {"backlash_pos_deg": -10.0},
                    {"backlash_pos_deg": -10.0}).values
    assert values["backlash_pos_deg"] == pytest.approx((LINE_END_DEG + 10.0,))


def test_no_play_is_searched_where_the_sheets_offset_is_small() -> None:
    small = -(MIN_PLAY_DEG - 0.5)
    values = engage(falling_sweep(LINE_END_DEG + 2.0), {"backlash_pos_deg": small},
                    {"backlash_pos_deg": small}).values
    assert values == {}


def test_the_calibrations_correction_takes_the_step_instead_of_the_sheets_offset() -> None:
    r = corrected(falling_sweep(16.0), play_offset(-10.0), 0.0)
    assert r.values["backlash_pos_deg"][0] == pytest.approx(16.0, abs=0.3)
    assert r.offset_u95_deg["backlash_pos_deg"] == pytest.approx(0.5)
    assert r.own_offset_deg["backlash_pos_deg"] == pytest.approx(LINE_END_DEG - 16.0, abs=0.3)


def test_the_step_is_found_on_the_grid_between_samples() -> None:
    grid = np.arange(0.0, 60.0, 0.25)
    travel = engage_travel_deg(grid, release_y(grid, 12.1), round(LINE_END_DEG / 0.25),
                               NOISE_A, (5.0, 20.0))
    assert travel == pytest.approx(12.1, abs=0.2)


def test_the_step_is_moved_to_where_the_tip_has_moved_the_sheets_one_degree() -> None:
    r = corrected(falling_sweep(16.0), play_offset(-10.0), 0.0, release_slope=1.25)
    assert r.values["backlash_pos_deg"][0] == pytest.approx(16.0 + 1.0 / 1.25, abs=0.3)
    assert r.own_offset_deg["backlash_pos_deg"] == pytest.approx(LINE_END_DEG - 16.8, abs=0.3)
    assert engage_lag_deg(None) == 0.0


def test_the_tips_move_is_the_truths_threshold() -> None:
    assert TIP_MOVE_DEG == TIP_THRESHOLD_DEG
