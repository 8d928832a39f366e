"""The data sheet's hold at home (tsmd.datasheet_home_hold): the field on the sheet, copied by
calibration into each unit's profile, and the stage's choice per knob from the sheet unit's
rows at rest (a knob keeps the hold only where no such row's tip error rises in either plane
beyond that row's seed noise and the sum falls)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from test_compensation_level_grid import params
from test_compensation_tension_play_fit import DEVICE_KNOB, synthetic_sweep

from tsmd.calibration.tension_play_fit import fit_tension_play
from tsmd.compensation.safety import KnobLimits
from tsmd.datasheet_home_hold import HomeHoldScore, RestRow, rest_rows, with_hold
from tsmd.profile import CatheterProfile, KnobProfile, ProfileError, ReferencePoint
from tsmd.profile.device import DeviceKnob, DeviceModel
from tsmd.profile.sheet_schema import device_model_from_mapping, device_model_to_mapping


def sheet(hold: tuple[bool, bool]) -> DeviceModel:
    knob = DeviceKnob(1.3, ReferencePoint(90.0, 70.0), ReferencePoint(-90.0, -72.0),
                      KnobLimits(-90.0, 90.0, 120.0, 2000.0))
    return DeviceModel("family-test", (knob, knob)).with_knob_flag("hold_at_home", hold)


def test_the_data_sheet_round_trips_the_hold_per_knob_and_writes_it_only_where_set() -> None:
    device = sheet((True, False))
    mapping = device_model_to_mapping(device)
    assert mapping["knobs"]["phi1"]["hold_at_home"] is True
    assert "hold_at_home" not in mapping["knobs"]["phi2"]
    assert device_model_from_mapping(mapping) == device


def test_a_sheet_hold_that_is_not_a_flag_is_refused_naming_the_key() -> None:
    mapping = device_model_to_mapping(sheet((False, False)))
    mapping["knobs"]["phi2"]["hold_at_home"] = "yes"
    with pytest.raises(ProfileError, match=r"knobs.phi2.hold_at_home"):
        device_model_from_mapping(mapping)


def test_calibration_copies_the_sheets_hold_into_the_profile() -> None:
    sweeps = [synthetic_sweep(g) for g in (-90.0, 0.0, 90.0)]
    plain = fit_tension_play(sweeps, DEVICE_KNOB)
    held = fit_tension_play(sweeps, dataclasses.replace(DEVICE_KNOB, hold_at_home=True))
    assert not plain.hold_at_home
    assert held == dataclasses.replace(plain, hold_at_home=True)


def row(rest: tuple[float, float], moving: tuple[float, float], noise: float = 0.0) -> RestRow:
    return RestRow("row", rest[0], rest[1], moving[0], moving[1], noise, noise)


def test_a_knob_takes_the_hold_where_every_row_at_rest_tracks_better_with_it() -> None:
    score = HomeHoldScore(0, (row((2.0, 1.0), (3.0, 3.0)), row((1.0, 0.9), (2.0, 1.9))))
    assert score.chosen


def test_a_row_whose_moving_plane_loses_keeps_the_hold_off_even_where_the_sum_gains() -> None:
    # pronyring unit 0's phi1 at rest: the resting tip much better, the moving plane worse
    # through the shared sheath (the plane a 1-DOF row scores)
    trade = row((2.40, 1.09), (2.71, 2.94))
    assert trade.mse_change < 0.0
    assert not HomeHoldScore(0, (trade, row((2.30, 1.04), (2.12, 2.05)))).chosen


def test_a_rise_within_the_rows_seed_noise_does_not_count_as_a_loss() -> None:
    # planetwist unit 0's phi2 at rest: the moving plane 2.052 -> 2.052 (+1e-4)
    within = row((2.60, 1.10), (2.0520, 2.0521), noise=0.003)
    assert HomeHoldScore(1, (within,)).chosen
    assert not HomeHoldScore(1, (row((2.60, 1.10), (2.0520, 2.0521)),)).chosen


def test_a_rise_beyond_the_rows_seed_noise_counts_as_a_loss() -> None:
    # jawcrimp unit 0's phi2 at rest (session 27): the moving phi1 1.303 -> 1.346
    assert not HomeHoldScore(1, (row((2.13, 1.64), (1.303, 1.346), noise=0.01),)).chosen


def test_a_row_whose_resting_plane_loses_keeps_the_hold_off() -> None:
    assert not HomeHoldScore(1, (row((2.0, 1.0), (3.0, 3.0)), row((1.0, 1.1), (2.0, 1.5)))).chosen


def test_a_hold_that_changes_nothing_stays_off() -> None:
    assert not HomeHoldScore(0, (row((1.0, 1.0), (2.0, 2.0)),) * 2).chosen
    assert not HomeHoldScore(0, ()).chosen


@pytest.mark.parametrize("knob", [0, 1])
def test_the_rows_at_rest_are_the_paper_rows_where_only_the_other_knob_moves(knob: int) -> None:
    rows = rest_rows(knob)
    assert [s.group for s in rows] == ["1-DOF periodic", "1-DOF non-periodic"]
    for s in rows:
        assert s.knobs == (1 - knob,)
        assert not np.any(s.q_deg[:, knob]) and np.ptp(s.q_deg[:, 1 - knob]) > 60.0


def test_the_hold_is_set_in_the_unit_profile_per_knob() -> None:
    knob = KnobProfile(1.3, ReferencePoint(90.0, 70.0), ReferencePoint(-90.0, -72.0), -3.0,
                       4.0, (-90.0, 90.0), (20.0, 20.0), (-22.0, -22.0), (5.0, 5.0),
                       (5.0, 5.0), params())
    profile = CatheterProfile("c", "family-test", "now", "0", "pchip", (knob, knob))
    held = with_hold(profile, (False, True))
    assert [k.tension_play.hold_at_home for k in held.knobs if k.tension_play] == [False, True]
