"""The gain the product's release-path ratio is taken against, and the sheet's tip backlash
gain it is chosen by (session 16; read at the lines' corners: session 17)."""

from __future__ import annotations

import dataclasses
import math

import pytest
from support.profiles import DEVICE, assert_sheet_knob_field_round_trips

from tsmd.compensation.release_ratio import ratio_gain, release_slope_ratio
from tsmd.compensation.safety import KnobLimits
from tsmd.datasheet_amplitude import backlash_growth
from tsmd.profile import (
    DeviceKnob,
    ProfileError,
    ReferencePoint,
    device_model_from_mapping,
    device_model_to_mapping,
    load_device_model,
)

SETTLE, RULE, OMEGA, RELEASE = 0.2, 0.16, 1.32, 1.51
KNOB = DeviceKnob(OMEGA, ReferencePoint(90.0, 81.0), ReferencePoint(-90.0, -81.0),
                  KnobLimits(-90.0, 90.0, 120.0, 2000.0), release_omega=RELEASE,
                  reference_backlash_gain=SETTLE, reference_rule_backlash_gain=RULE)


def moved_gain(gain: float) -> float:
    """The sheet unit's own gain after the release line is moved to the ratio against ``gain``."""
    return 1.0 - OMEGA * (1.0 - RULE) / (RELEASE * (1.0 - gain))


def test_without_the_tip_gain_the_ratio_is_against_the_settle_rules_gain() -> None:
    assert ratio_gain(KNOB) == SETTLE
    assert release_slope_ratio(KNOB) == pytest.approx(RELEASE * (1 - SETTLE) / OMEGA)


def test_a_tip_gain_near_the_rule_readings_moved_gain_takes_the_rule_reading() -> None:
    knob = dataclasses.replace(KNOB, reference_tip_backlash_gain=moved_gain(RULE) + 0.005)
    assert ratio_gain(knob) == RULE
    assert release_slope_ratio(knob) == pytest.approx(RELEASE * (1 - RULE) / OMEGA)


def test_a_tip_gain_near_the_settle_readings_moved_gain_keeps_the_settle_reading() -> None:
    knob = dataclasses.replace(KNOB, reference_tip_backlash_gain=moved_gain(SETTLE) - 0.005)
    assert ratio_gain(knob) == SETTLE


def test_a_sheet_without_the_rule_gain_keeps_the_settle_reading() -> None:
    knob = dataclasses.replace(KNOB, reference_rule_backlash_gain=None,
                               reference_tip_backlash_gain=moved_gain(RULE))
    assert ratio_gain(knob) == SETTLE


def test_the_tip_gain_round_trips_and_is_range_checked() -> None:
    assert_sheet_knob_field_round_trips("reference_tip_backlash_gain", 0, 0.126, -0.1)


def test_the_tip_gain_is_the_mean_backlash_growth_per_degree_of_amplitude() -> None:
    assert backlash_growth((6.0, 7.0), (9.0, 11.0), 60.0, 90.0) == pytest.approx(3.5 / 30.0)


def test_a_side_without_a_backlash_gives_no_tip_gain() -> None:
    assert backlash_growth((6.0, math.nan), (9.0, 11.0)) is None


def test_a_line_read_tip_gain_decides_over_the_threshold_read_one() -> None:
    knob = dataclasses.replace(KNOB, reference_tip_backlash_gain=moved_gain(SETTLE),
                               reference_tip_line_backlash_gain=moved_gain(RULE) + 0.005)
    assert ratio_gain(knob) == RULE
    assert release_slope_ratio(knob) == pytest.approx(RELEASE * (1 - RULE) / OMEGA)


def test_a_line_read_tip_gain_alone_chooses_the_gain() -> None:
    knob = dataclasses.replace(KNOB, reference_tip_line_backlash_gain=moved_gain(SETTLE) - 0.005)
    assert ratio_gain(knob) == SETTLE


def test_the_line_read_tip_gain_round_trips_and_is_range_checked() -> None:
    assert_sheet_knob_field_round_trips("reference_tip_line_backlash_gain", 1, 0.173, 0.9)


def test_the_sheets_ratio_gain_choice_overrides_the_tip_gains() -> None:
    near_settle = moved_gain(SETTLE) - 0.005
    knob = dataclasses.replace(KNOB, reference_tip_backlash_gain=near_settle,
                               release_ratio_gain="rule")
    assert ratio_gain(knob) == RULE
    assert ratio_gain(dataclasses.replace(knob, release_ratio_gain="settle")) == SETTLE


def test_the_ratio_gain_choice_round_trips_and_an_unknown_one_is_refused() -> None:
    data = device_model_to_mapping(load_device_model(DEVICE))
    data["knobs"]["phi2"]["release_ratio_gain"] = "settle"
    device = device_model_from_mapping(data)
    assert device.knobs[1].release_ratio_gain == "settle"
    assert device.knobs[0].release_ratio_gain is None
    assert device_model_to_mapping(device)["knobs"]["phi2"]["release_ratio_gain"] == "settle"
    data["knobs"]["phi2"]["release_ratio_gain"] = "tip"
    with pytest.raises(ProfileError, match="knobs.phi2.release_ratio_gain: 'tip'"):
        device_model_from_mapping(data)


def test_a_ratio_gain_choice_without_its_gain_is_refused() -> None:
    data = device_model_to_mapping(load_device_model(DEVICE))
    data["knobs"]["phi1"].pop("reference_rule_backlash_gain", None)
    data["knobs"]["phi1"]["release_ratio_gain"] = "rule"
    with pytest.raises(ProfileError, match="needs reference_rule_backlash_gain"):
        device_model_from_mapping(data)
