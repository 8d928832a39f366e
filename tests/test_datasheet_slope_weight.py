"""The product's share of a gain reading's slope change, chosen on its sample's tracked tips."""

from __future__ import annotations

import dataclasses
import math

import pytest
from test_compensation_tension_play_fit import DEVICE_KNOB, synthetic_sweep

from tsmd.calibration.tension_play_fit import fit_tension_play
from tsmd.config import resolve_data_path
from tsmd.datasheet_slope_weight import SlopePair, slope_weight, with_slope_weight
from tsmd.profile import device_model_from_mapping, device_model_to_mapping, load_device_model


def _pairs(readings: list[float], tips: list[float]) -> list[SlopePair]:
    return [SlopePair(str(i), r, t) for i, (r, t) in enumerate(zip(readings, tips, strict=True))]


def test_tips_that_follow_the_readings_give_the_whole_move() -> None:
    r = [1.0, 1.05, 0.95, 1.03]
    assert slope_weight(_pairs(r, r)) == pytest.approx(1.0)


def test_tips_that_follow_a_share_of_the_readings_give_that_share() -> None:
    r = [1.0, 1.05, 0.95, 1.03]
    assert slope_weight(_pairs(r, [1 + 0.3 * (x - 1) for x in r])) == pytest.approx(0.3)


def test_tips_that_ignore_the_readings_give_none_of_it() -> None:
    # wormeyelet-like: the gain moves both ways while the tips stay near the sheet's slope
    assert slope_weight(_pairs([1.046, 0.951, 1.035, 1.02], [1.0, 1.01, 0.99, 0.98])) == 0.0


def test_the_share_stays_within_none_and_all() -> None:
    r = [1.0, 1.05, 0.95]
    assert slope_weight(_pairs(r, [1 + 2 * (x - 1) for x in r])) == 1.0
    assert slope_weight(_pairs(r, [1 - (x - 1) for x in r])) == 0.0


def test_readings_that_hardly_move_choose_nothing() -> None:
    assert slope_weight(_pairs([1.0, 1.002, 0.998], [1.0, 1.05, 0.95])) is None


def test_a_missing_reading_is_left_out() -> None:
    r = [1.0, 1.05, 0.95]
    pairs = [*_pairs(r, [1 + 0.5 * (x - 1) for x in r]), SlopePair("x", math.nan, 1.2)]
    assert slope_weight(pairs) == pytest.approx(0.5)


def _sheet():  # type: ignore[no-untyped-def]
    return load_device_model(resolve_data_path("profiles/devices/family/wormeyelet.yaml"))


def test_the_sheet_carries_each_knobs_weight_and_reads_it_back() -> None:
    pairs = [(SlopePair("0", 1.0, 1.0), SlopePair("0", 1.0, 1.0)),
             (SlopePair("201", 1.05, 1.02), SlopePair("201", 1.004, 1.03)),
             (SlopePair("202", 0.95, 0.98), SlopePair("202", 0.997, 0.96))]
    device, weights = with_slope_weight(_sheet(), pairs)
    assert weights[0] == pytest.approx(0.4) and weights[1] is None
    back = device_model_from_mapping(device_model_to_mapping(device))
    assert back.knobs[0].slope_gain_weight == pytest.approx(0.4)
    assert back.knobs[1].slope_gain_weight is None


def test_a_weight_outside_none_and_all_is_refused() -> None:
    m = device_model_to_mapping(_sheet())
    m["knobs"]["phi1"]["slope_gain_weight"] = 1.5
    with pytest.raises(ValueError, match="slope_gain_weight"):
        device_model_from_mapping(m)


def test_a_sheets_weight_moves_the_units_fitted_omega_by_that_share() -> None:
    grid = (-90.0, 0.0, 90.0)
    knob = dataclasses.replace(DEVICE_KNOB, reference_backlash_gain=0.2)
    sweeps = [dataclasses.replace(synthetic_sweep(g, backlash_deg=15.0),
                                  settle_backlash_deg=(30.0, 30.0)) for g in grid]
    full = fit_tension_play(sweeps, knob).omega
    none = fit_tension_play(sweeps, dataclasses.replace(knob, slope_gain_weight=0.0)).omega
    half = fit_tension_play(sweeps, dataclasses.replace(knob, slope_gain_weight=0.5)).omega
    assert full != pytest.approx(DEVICE_KNOB.omega, abs=0.01)
    assert none == pytest.approx(DEVICE_KNOB.omega)
    assert half == pytest.approx(0.5 * (full + DEVICE_KNOB.omega))
