"""Drive configuration and unit conversion."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from drivers.units import DriveConfig, DriveConfigError, interpolation_period


def test_counts_per_degree_include_encoder_and_gear():
    cfg = DriveConfig(node_id=1, counts_per_motor_rev=4096, gear_ratio=90.0)
    assert cfg.counts_per_deg == pytest.approx(4096 * 90 / 360)
    assert cfg.deg_to_counts(1.0) == 1024


@given(st.floats(min_value=-180, max_value=180))
def test_degrees_round_trip_within_one_count(deg):
    cfg = DriveConfig(node_id=1)
    assert abs(cfg.counts_to_deg(cfg.deg_to_counts(deg)) - deg) <= 0.5 / cfg.counts_per_deg


def test_raw_current_scale_and_saturation():
    cfg = DriveConfig(node_id=1, current_scale_A=0.002)
    assert cfg.raw_to_A(100) == pytest.approx(0.2)
    assert cfg.A_to_raw(0.2) == 100
    assert cfg.A_to_raw(1e6) == 32767
    assert cfg.rated_current_mA == 2000


def test_from_dict_accepts_nested_identity():
    cfg = DriveConfig.from_dict({"node_id": 3, "identity": {"vendor_id": 0x9A, "product_code": 7},
                                 "gear_ratio": 66})
    assert (cfg.node_id, cfg.vendor_id, cfg.product_code, cfg.gear_ratio) == (3, 0x9A, 7, 66.0)


@pytest.mark.parametrize(("data", "message"), [
    ({}, "'node_id' is missing"),
    ({"node_id": 1, "gear": 3}, r"unknown drive key\(s\): \['gear'\]"),
    ({"node_id": 1, "gear_ratio": "x"}, "'gear_ratio': 'x' is not a number"),
    ({"node_id": 1.5}, "'node_id': 1.5 must be an integer"),
    ({"node_id": 200}, "'node_id'=200: must be 1..127"),
    ({"node_id": 1, "min_deg": 10, "max_deg": 0}, "'min_deg'=10.0: must be < max_deg"),
    ({"node_id": 1, "heartbeat_producer_ms": 200}, "'heartbeat_timeout_ms'=150"),
    ({"node_id": 1, "quick_stop_option": 3}, "'quick_stop_option'=3"),
    ({"node_id": 1, "identity": {"serial": 1}}, r"unknown drive identity key\(s\)"),
])
def test_from_dict_names_the_bad_key(data, message):
    with pytest.raises(DriveConfigError, match=message):
        DriveConfig.from_dict(data)


@pytest.mark.parametrize(("period_s", "expected"), [
    (0.004, (4, -3)), (0.001, (1, -3)), (0.0025, (25, -4)), (0.01, (10, -3)),
    (0.0005, (5, -4))])
def test_interpolation_period_encoding(period_s, expected):
    assert interpolation_period(period_s) == expected


def test_interpolation_period_rejects_non_positive():
    with pytest.raises(DriveConfigError, match="must be > 0"):
        interpolation_period(0.0)
