"""A miss of one sign on every unit of the product's sample is the product's: the units' mean is
subtracted from every unit's reported value and the unit part is the scatter about it; our
compensator's frame is not moved (docs/calibration.md, session 28)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from support.calibration import sweep_recording

from tsmd.calibration import Sweep
from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.identify import IdentifyOptions
from tsmd.calibration.run import identify_recording
from tsmd.calibration.sample_offset import (
    MIN_SIGN_UNITS,
    one_sided_offset_deg,
    sheet_offsets_deg,
    with_sample_offset,
)
from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import HalfCycle, SweepResult
from tsmd.calibration.unit_part import UnitPart
from tsmd.datasheet_sample import one_sided_offsets, sample_readings, with_offsets
from tsmd.profile import load_device_model, save_device_model
from tsmd.recording import Recording

ROOT = Path(__file__).resolve().parent.parent
DEVICE = ROOT / "profiles" / "devices" / "sim-catheter.yaml"
INSIDE = (-0.68, -0.92, -0.75, -0.81, -0.70, -0.88, -0.77, -0.85, -0.72)
"""Nine units' mean D_pos misses, all inside the tip (capstan's sample, session 27's shape)."""


def _sweep() -> SweepResult:
    t = np.arange(10) * 0.01
    data = Conditioned(t, t, t, t, t, 100.0, 0.001, 0.0005, ())
    halves = (HalfCycle(1, 0, 5, True, backlash_deg=20.0),)
    return SweepResult(data, halves, {"dead_zone_pos_deg": (15.0, 15.5),
                                      "backlash_neg_deg": (20.0, 21.0)},
                       unseen={"backlash_neg_deg": 1.0})


def test_every_unit_missing_on_one_side_gives_the_units_mean() -> None:
    assert one_sided_offset_deg(INSIDE) == pytest.approx(float(np.mean(INSIDE)))


def test_misses_of_either_sign_are_scatter_and_give_no_offset() -> None:
    assert one_sided_offset_deg((*INSIDE[:-1], 0.05)) == 0.0


def test_too_few_units_to_tell_a_side_give_no_offset() -> None:
    assert one_sided_offset_deg(INSIDE[:MIN_SIGN_UNITS - 1]) == 0.0
    assert one_sided_offset_deg(INSIDE[:MIN_SIGN_UNITS]) != 0.0


def test_the_offset_moves_the_values_by_itself() -> None:
    moved = with_sample_offset(_sweep(), {"dead_zone_pos_deg": -0.8})
    assert moved.values["dead_zone_pos_deg"] == pytest.approx((15.8, 16.3))


def test_a_backlash_the_current_does_not_show_is_not_moved() -> None:
    moved = with_sample_offset(_sweep(), {"backlash_neg_deg": 0.5})
    assert moved.values["backlash_neg_deg"] == (20.0, 21.0)


def test_the_sheet_carries_the_offsets_through_a_file(tmp_path: Path) -> None:
    device = with_offsets(load_device_model(DEVICE), {(0, "dead_zone_pos_deg"): -0.79,
                                                      (1, "backlash_neg_deg"): 0.4})
    save_device_model(device, tmp_path / "d.yaml")
    back = load_device_model(tmp_path / "d.yaml")
    assert sheet_offsets_deg(back.knobs[0]) == {"dead_zone_pos_deg": -0.79}
    assert sheet_offsets_deg(back.knobs[1]) == {"backlash_neg_deg": 0.4}


# --- the sample stage ---------------------------------------------------------------------------


@dataclasses.dataclass
class _Run:
    points: list[object]


def _runs(misses_deg: tuple[float, ...]) -> list[tuple[_Run, dict]]:
    """One run per unit: one grid point of knob 0 whose D_pos misses its tip by the unit's miss
    (the other parameters exact), two agreeing half-cycles."""
    out = []
    for miss in misses_deg:
        values = {"dead_zone_pos_deg": (15.0 + miss,) * 2, "dead_zone_neg_deg": (-15.0,) * 2,
                  "backlash_pos_deg": (10.0,) * 2, "backlash_neg_deg": (10.0,) * 2}
        result = dataclasses.replace(_sweep(), values=values, unseen={})
        truth = {(0, 0.0): {"dead_zone_pos_deg": 15.0, "dead_zone_neg_deg": -15.0,
                            "backlash_pos_deg": 10.0, "backlash_neg_deg": 10.0}}
        out.append((_Run([GridPoint(0, 0.0, result)]), truth))
    return out


def test_the_sample_stage_finds_the_one_sided_miss() -> None:
    offsets = one_sided_offsets(_runs(INSIDE))  # type: ignore[arg-type]
    assert offsets == {(0, "dead_zone_pos_deg"): pytest.approx(np.mean(INSIDE), abs=0.005)}


def test_the_sample_stages_part_reads_the_scatter_about_the_offset() -> None:
    runs = _runs(INSIDE)
    offsets = one_sided_offsets(runs)  # type: ignore[arg-type]
    before = sample_readings(runs)  # type: ignore[arg-type]
    after = sample_readings(runs, offsets)  # type: ignore[arg-type]
    d_before = np.abs(before[(0, "dead-zone edge")][0])
    d_after = np.abs(after[(0, "dead-zone edge")][0])
    assert d_before.max() > 0.6 and d_after.max() < 0.15


# --- a calibration ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def sweep_rec() -> Recording:
    return sweep_recording(Sweep(0, 0.0, 90.0, 0.1, 1.5, "triangle"))


def test_a_calibration_reports_the_value_less_the_offset_and_fits_the_value_as_read(
        sweep_rec: Recording) -> None:
    part = UnitPart(0.3, 0.3, (("dead_zone_pos_deg", -0.8),))
    plain = identify_recording(sweep_rec, IdentifyOptions(unit_part=UnitPart(0.3, 0.3)))
    point = identify_recording(sweep_rec, IdentifyOptions(unit_part=part))
    read = plain.result.estimate("dead_zone_pos_deg")
    assert point.result.estimate("dead_zone_pos_deg") == pytest.approx(read + 0.8)
    assert point.in_model_frame().result.estimate("dead_zone_pos_deg") == pytest.approx(read)
    assert point.result.estimate("dead_zone_neg_deg") == plain.result.estimate(
        "dead_zone_neg_deg")
