"""The sheet unit's edges as its own calibration reads them, and ours' plateau heights drawn
through them (session 26)."""

from __future__ import annotations

import dataclasses

import pytest
from support.profiles import assert_sheet_knob_field_round_trips, make_profile
from support.tension_sweeps import D_NEG, D_POS, SHEET_KNOB, sweep

from tsmd.calibration.reading_offset import calibrated_edges
from tsmd.calibration.tension_play_fit import fit_tension_play
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.datasheet_unit_edges import edges_at_zero, with_edges_of
from tsmd.profile import DeviceKnob, DeviceModel


def fitted(knob: DeviceKnob) -> tuple[float, float]:
    p = fit_tension_play([sweep(g) for g in (-90.0, 0.0, 90.0)], knob)
    return p.height_pos_deg, p.height_neg_deg


def test_plateau_heights_are_drawn_through_the_sheet_units_calibrated_edges() -> None:
    knob = dataclasses.replace(SHEET_KNOB, calibrated_dead_zone_pos_deg=22.0,
                               calibrated_dead_zone_neg_deg=-23.0)
    h_pos, h_neg = fitted(knob)
    assert h_pos == pytest.approx(100.0 - 1.5 * (90.0 - 22.0))
    assert h_neg == pytest.approx(-100.0 + 1.5 * (90.0 - 23.0))


def test_without_calibrated_edges_the_reference_edges_draw_the_heights() -> None:
    h_pos, h_neg = fitted(SHEET_KNOB)
    assert h_pos == pytest.approx(100.0 - 1.5 * (90.0 - 25.0))
    assert h_neg == pytest.approx(-100.0 + 1.5 * (90.0 - 25.0))


def test_one_calibrated_side_alone_leaves_the_edges_as_given() -> None:
    knob = dataclasses.replace(SHEET_KNOB, calibrated_dead_zone_pos_deg=22.0)
    assert calibrated_edges(knob, 25.0, -25.0) == (25.0, -25.0)
    assert fitted(knob) == fitted(SHEET_KNOB)


def test_the_units_own_edges_stay_its_own_with_calibrated_sheet_edges() -> None:
    knob = dataclasses.replace(SHEET_KNOB, calibrated_dead_zone_pos_deg=22.0,
                               calibrated_dead_zone_neg_deg=-23.0)
    p = fit_tension_play([sweep(g) for g in (-90.0, 0.0, 90.0)], knob)
    assert p.dead_zone_pos_deg == (D_POS,) * 3
    assert p.dead_zone_neg_deg == (D_NEG,) * 3


def test_sheet_gets_each_knobs_profile_edges_at_the_other_knobs_zero() -> None:
    profile = make_profile(d0=21.0)  # edges d0 - |other| / 30 over the grid
    knob = dataclasses.replace(SHEET_KNOB, calibrated_dead_zone_pos_deg=None)
    sheet = with_edges_of(DeviceModel("m", (knob, knob)), [profile])
    for k, pk in zip(sheet.knobs, profile.knobs, strict=True):
        assert pk.tension_play is not None
        assert k.calibrated_dead_zone_pos_deg == pytest.approx(21.0)
        assert k.calibrated_dead_zone_neg_deg == pytest.approx(-21.0)
        assert (k.calibrated_dead_zone_pos_deg, k.calibrated_dead_zone_neg_deg) == \
            pytest.approx(edges_at_zero(pk.tension_play), abs=0.01)
        assert k.reference_dead_zone_pos_deg == 25.0  # the tracked sweep's edge is kept


def test_edges_at_zero_are_read_between_grid_points_without_zero() -> None:
    params = TensionPlayParams(1.5, -5.0, 5.0, (-60.0, 60.0), (18.0, 22.0), (-24.0, -20.0),
                               (0.1, 0.1), (0.1, 0.1), (5.0, 5.0), (-5.0, -5.0))
    assert edges_at_zero(params) == pytest.approx((20.0, -22.0))


def test_sheet_keys_round_trip_and_their_range() -> None:
    assert_sheet_knob_field_round_trips("calibrated_dead_zone_pos_deg", 1, 19.6, 95.0)
    assert_sheet_knob_field_round_trips("calibrated_dead_zone_neg_deg", 0, -20.8, 5.0)


def test_sheet_edges_are_the_mean_over_the_sheet_units_runs() -> None:
    runs = [make_profile(d0=20.0), make_profile(d0=21.0)]
    sheet = with_edges_of(DeviceModel("m", (SHEET_KNOB, SHEET_KNOB)), runs)
    assert sheet.knobs[0].calibrated_dead_zone_pos_deg == pytest.approx(20.5)
    assert sheet.knobs[1].calibrated_dead_zone_neg_deg == pytest.approx(-20.5)
