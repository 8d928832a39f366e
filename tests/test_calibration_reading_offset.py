"""The product's reading offset: measured on the sheet's unit, applied per side and other-knob
angle where sure, carried into the gate, absent from a sheet without it."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace
from typing import Any

import pytest
from support.profiles import DEVICE as DEVICE_PATH

from tsmd.calibration.estimate import point_estimates
from tsmd.calibration.reading_offset import corrected, offset_at, reference_edge_deg
from tsmd.calibration.run import device_options
from tsmd.calibration.sweep_result import SweepResult
from tsmd.datasheet_offset import offset_readings, reading_offsets
from tsmd.profile import (
    ProfileError,
    device_model_from_mapping,
    device_model_to_mapping,
    load_device_model,
)
from tsmd.profile.reading_offset import OffsetGrid, ReadingOffset

GRID = (-90.0, 0.0, 90.0)
DEVICE = load_device_model(DEVICE_PATH)


def offset(**grids: tuple[tuple[float, ...], tuple[float, ...]]) -> ReadingOffset:
    return ReadingOffset(GRID, tuple((name, OffsetGrid(mean, u95, (4, 4, 4)))
                                     for name, (mean, u95) in grids.items()))


def result(**values: tuple[float, ...]) -> SweepResult:
    return SweepResult(None, (), dict(values))  # type: ignore[arg-type]


def test_each_side_gets_its_own_offset_at_the_other_knobs_angle() -> None:
    o = offset(backlash_pos_deg=((3.0, 0.0, -2.0), (0.5, 0.0, 0.5)),
               backlash_neg_deg=((-4.0, 0.0, 5.0), (0.5, 0.0, 0.5)))
    r = corrected(result(backlash_pos_deg=(10.0, 11.0), backlash_neg_deg=(10.0, 11.0)), o, 90.0)
    assert r.values["backlash_pos_deg"] == pytest.approx((12.0, 13.0))
    assert r.values["backlash_neg_deg"] == pytest.approx((5.0, 6.0))
    at_minus = corrected(result(backlash_pos_deg=(10.0,), backlash_neg_deg=(10.0,)), o, -90.0)
    assert at_minus.values["backlash_pos_deg"] == pytest.approx((7.0,))
    assert at_minus.values["backlash_neg_deg"] == pytest.approx((14.0,))


def test_between_the_sheets_angles_the_offset_is_interpolated() -> None:
    o = offset(backlash_pos_deg=((3.0, 0.0, -2.0), (0.5, 0.0, 0.5)))
    assert offset_at(o, "backlash_pos_deg", 45.0) == pytest.approx((-1.0, 0.25))
    assert offset_at(o, "backlash_pos_deg", -120.0)[0] == pytest.approx(3.0)


def test_an_offset_measured_inconsistently_or_small_is_not_applied() -> None:
    o = offset(backlash_pos_deg=((3.0, 0.8, 2.0), (3.5, 0.1, 0.5)))
    r = corrected(result(backlash_pos_deg=(10.0, 11.0)), o, -90.0)  # 3 +- 3.5: not sure
    assert r.values["backlash_pos_deg"] == (10.0, 11.0)
    small = corrected(result(backlash_pos_deg=(10.0, 11.0)), o, 0.0)  # 0.8 +- 0.1: too small
    assert small.values["backlash_pos_deg"] == (10.0, 11.0)


def test_a_sheet_without_an_offset_leaves_the_values_as_read() -> None:
    r = result(backlash_pos_deg=(10.0, 11.0))
    assert corrected(r, None, 90.0) is r
    assert all(o.reading_offset is None for o in device_options(None, DEVICE))


def test_the_gate_sees_the_applied_offsets_uncertainty_which_no_resweep_narrows() -> None:
    o = offset(backlash_pos_deg=((3.0, 3.0, 3.0), (1.5, 1.5, 1.5)))
    r = corrected(result(backlash_pos_deg=(10.0, 10.1), dead_zone_pos_deg=(20.0, 20.1)), o, 0.0)
    plain = point_estimates([result(backlash_pos_deg=(10.0, 10.1))])[0]["backlash_pos_deg"]
    e = point_estimates([r])[0]["backlash_pos_deg"]
    assert e.u95_deg == pytest.approx(math.hypot(plain.u95_deg, 1.5))
    assert e.tip_cost_with_deg(1.0, 1000) >= 1.5


def test_the_sheets_offset_is_each_half_cycle_minus_the_tip_per_angle() -> None:
    def point(knob: int, other: float, b_pos: tuple[float, ...]) -> Any:
        return SimpleNamespace(knob=knob, other_deg=other,
                               result=result(backlash_pos_deg=b_pos))

    runs: Any = [SimpleNamespace(points=[point(0, -90.0, (13.0, 13.2)), point(0, 0.0, (10.0, 10.1)),
                                         point(0, 90.0, (7.0, 7.2))]),
                 SimpleNamespace(points=[point(0, -90.0, (13.1, 12.9)), point(0, 0.0, (10.2, 9.9)),
                                         point(0, 90.0, (7.1, 6.9))])]
    truth = {(0, a): {"backlash_pos_deg": 10.0} for a in GRID}
    phi1, phi2 = reading_offsets(offset_readings(runs, truth))
    assert phi2 is None and phi1 is not None
    g = phi1.grid("backlash_pos_deg")
    assert g is not None and g.half_cycles == (4, 4, 4)
    assert g.mean_deg == pytest.approx((3.05, 0.05, -2.95), abs=0.06)
    assert all(0 < u < 1 for u in g.u95_deg)


def test_a_sheets_offset_round_trips_and_a_wrong_one_is_one_error_line() -> None:
    o = offset(backlash_neg_deg=((1.0, 2.0, 3.0), (0.1, 0.2, 0.3)))
    sheet = dataclasses.replace(DEVICE, knobs=(dataclasses.replace(DEVICE.knobs[0],
                                                                   reading_offset=o),
                                               DEVICE.knobs[1]))
    m = device_model_to_mapping(sheet)
    assert device_model_from_mapping(m) == sheet
    m["knobs"]["phi1"]["reading_offset"]["backlash_neg_deg"]["mean_deg"] = [1.0, 2.0]
    with pytest.raises(ProfileError) as err:
        device_model_from_mapping(m, "sheet.yaml")
    assert "\n" not in str(err.value)
    assert "knobs.phi1.reading_offset" in str(err.value)


def test_the_sheets_reference_edge_is_corrected_like_the_units_edges() -> None:
    o = offset(dead_zone_pos_deg=((-1.5, -1.5, -1.5), (0.3, 0.3, 0.3)))
    assert reference_edge_deg(o, "dead_zone_pos_deg", 20.0) == pytest.approx(21.5)
    assert reference_edge_deg(o, "dead_zone_neg_deg", -20.0) == -20.0
    assert reference_edge_deg(None, "dead_zone_pos_deg", 20.0) == 20.0
    assert reference_edge_deg(o, "dead_zone_pos_deg", None) is None
