"""The unit's backlash gain read as the data sheet read its own: B before the reading offset."""

from __future__ import annotations

import dataclasses

import pytest
from test_compensation_tension_play_fit import DEVICE_KNOB, X0_POS, synthetic_sweep

from tsmd.calibration.load_ramp import SideFit
from tsmd.calibration.read_gain import read_gain, read_side_ratio, subtracted_backlash_deg
from tsmd.calibration.tension_play_fit import fit_tension_play
from tsmd.compensation.tension_play import release_line
from tsmd.profile.reading_offset import OffsetGrid, ReadingOffset

GRID = (-90.0, 0.0, 90.0)


def offset_knob(shift_deg: float, ends_deg: float | None = None, **fields: float) -> object:
    """The test's sheet knob whose B reads ``shift_deg`` off the tip on both sides (at the
    other knob's ends ``ends_deg`` where given)."""
    end = shift_deg if ends_deg is None else ends_deg
    grid = OffsetGrid((end, shift_deg, end), (0.3,) * 3, (4,) * 3)
    offset = ReadingOffset(GRID, (("backlash_pos_deg", grid), ("backlash_neg_deg", grid)))
    return dataclasses.replace(DEVICE_KNOB, reading_offset=offset, **fields)


def test_the_offset_the_calibration_subtracted_is_added_back() -> None:
    fit = SideFit(20.0, 14.0, 90.0, 20.0, 0.2)
    assert read_gain(fit, -10.0) == pytest.approx(4.0 / 70.0)


def test_an_unseen_backlash_has_nothing_added_back() -> None:
    knob = offset_knob(-10.0)
    assert subtracted_backlash_deg(knob, (True, False)) == (0.0, -10.0)


def test_without_a_reading_offset_nothing_is_added_back() -> None:
    assert subtracted_backlash_deg(DEVICE_KNOB, (False, False)) == (0.0, 0.0)


def test_the_offset_added_back_is_the_one_where_the_sheet_read_its_gains() -> None:
    # only at the other knob's ends: the sheet's gains (other knob at 0) never saw it
    assert subtracted_backlash_deg(offset_knob(0.0, ends_deg=-2.0), (False, False)) == (0.0, 0.0)


def test_a_unit_that_reads_like_the_sheets_unit_keeps_the_sheets_omega() -> None:
    # B corrected to 25 deg; as read 25 - 15 = 10 deg, the sheet's rule gain read the same way
    raw = 10.0 / (90.0 - X0_POS)
    knob = offset_knob(-15.0, reference_rule_backlash_gain=raw)
    p = fit_tension_play([synthetic_sweep(g, backlash_deg=25.0) for g in GRID], knob)
    assert p.omega == pytest.approx(1.5, rel=0.01)


def test_the_release_line_has_the_ratio_times_the_read_gains_locus() -> None:
    ratio, gain, read = 0.95, 0.3, 0.1
    moved = 1.0 - (1.0 - gain) / read_side_ratio(ratio, gain, read)
    s, _ = release_line(1.5, 2.0, 20.0, moved, 10.0)
    assert s == pytest.approx(ratio * 1.5 / (1.0 - read))


def test_the_ratio_is_unchanged_where_the_gains_agree_or_there_is_no_ratio() -> None:
    assert read_side_ratio(0.95, 0.2, 0.2) == 0.95
    assert read_side_ratio(1.0, 0.3, 0.1) == 1.0


def test_a_unit_that_read_its_own_play_has_its_own_offset_added_back() -> None:
    # B 28 deg read at the play's end its current showed, 10 deg as the line rule read it:
    # the unit reads like the sheet's unit (own offset -18), whatever the sheet's offset says
    raw = 10.0 / (90.0 - X0_POS)
    knob = offset_knob(-15.0, reference_rule_backlash_gain=raw)
    sweeps = [dataclasses.replace(synthetic_sweep(g, backlash_deg=28.0),
                                  own_offset_deg=(-18.0, -18.0)) for g in GRID]
    assert fit_tension_play(sweeps, knob).omega == pytest.approx(1.5, rel=0.01)
    with_sheets = [synthetic_sweep(g, backlash_deg=28.0) for g in GRID]
    assert fit_tension_play(with_sheets, knob).omega < 1.48
