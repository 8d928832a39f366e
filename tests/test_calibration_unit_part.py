"""The product's part of the error no sweep narrows, measured on its sample and reported with
every value (docs/calibration.md, session 19)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from support.profiles import DEVICE

from tsmd.calibration.estimate import point_estimates
from tsmd.calibration.options import device_options
from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import HalfCycle, SweepResult
from tsmd.calibration.unit_part import Z95, UnitPart, sample_u95_deg, with_unit_part
from tsmd.cli import main
from tsmd.profile import (
    ProfileError,
    device_model_from_mapping,
    device_model_to_mapping,
    load_device_model,
)


def _sweep() -> SweepResult:
    t = np.arange(10) * 0.01
    data = Conditioned(t, t, t, t, t, 100.0, 0.001, 0.0005, ())
    halves = tuple(HalfCycle(1, 0, 5, True, backlash_deg=20.0, share_u95_deg=w)
                   for w in (1.0, 3.0))
    return SweepResult(data, halves, {"backlash_neg_deg": (20.0, 21.0),
                                      "dead_zone_pos_deg": (15.0, 15.5)})


def test_errors_the_gates_half_widths_explain_leave_no_product_part() -> None:
    rng = np.random.default_rng(0)
    errors = rng.normal(0.0, 0.5, 4000)
    assert sample_u95_deg(errors, np.full(errors.size, 0.5 * Z95), 1000) < 0.1


def test_a_bias_the_gate_does_not_see_is_the_product_part() -> None:
    errors = np.array([1.0, -1.0, 1.0, -1.0])
    # a large sample: the normal's 1.96 sigma
    assert sample_u95_deg(errors, np.zeros(4), 100000) == pytest.approx(Z95, rel=1e-3)


def test_a_small_sample_predicts_a_new_unit_with_a_wider_half_width() -> None:
    errors = np.array([1.0, -1.0, 1.0, -1.0])
    assert sample_u95_deg(errors, np.zeros(4), 4) > 1.5 * sample_u95_deg(errors, np.zeros(4), 100)


@pytest.mark.parametrize("errors, units, message", [([math.nan], 4, "no value"),
                                                    ([1.0], 1, "at least two")])
def test_a_sample_that_says_nothing_is_refused(errors: list[float], units: int,
                                               message: str) -> None:
    with pytest.raises(ValueError, match=message):
        sample_u95_deg(errors, [1.0], units)


def test_the_sheets_part_replaces_the_shares_and_reaches_the_dead_zone() -> None:
    (before,) = point_estimates([_sweep()])
    (after,) = point_estimates([with_unit_part(_sweep(), UnitPart(0.8, 1.5))])
    assert before["backlash_neg_deg"].unit_u95_deg == pytest.approx(2.0)  # the share's median
    assert before["dead_zone_pos_deg"].unit_u95_deg == 0.0
    assert after["backlash_neg_deg"].unit_u95_deg == pytest.approx(1.5)
    assert after["dead_zone_pos_deg"].unit_u95_deg == pytest.approx(0.8)
    assert after["dead_zone_pos_deg"].u95_deg == before["dead_zone_pos_deg"].u95_deg


def test_a_re_sweep_keeps_the_products_part() -> None:
    first = with_unit_part(_sweep(), UnitPart(0.8, None))
    assert first.merged(_sweep()).unit_u95_deg("dead_zone_pos_deg") == pytest.approx(0.8)


def test_a_sheet_without_a_sample_gives_no_part() -> None:
    shipped = load_device_model(DEVICE)  # capstan's sheet carries its sample's part (session 27)
    knobs = tuple(dataclasses.replace(k, dead_zone_unit_u95_deg=None, backlash_unit_u95_deg=None)
                  for k in shipped.knobs)
    device = dataclasses.replace(shipped, knobs=(knobs[0], knobs[1]))
    assert [o.unit_part for o in device_options(None, device)] == [None, None]


def test_the_sheets_parts_are_read_per_knob_and_written_back(tmp_path: Path) -> None:
    data = yaml.safe_load(DEVICE.read_text())
    for knob in ("phi1", "phi2"):  # capstan's sheet carries its sample (sessions 27, 28)
        for key in [k for k in data["knobs"][knob] if "unit_u95" in k or "sample_offset" in k]:
            data["knobs"][knob].pop(key)
    data["knobs"]["phi2"]["dead_zone_unit_u95_deg"] = 0.9
    data["knobs"]["phi2"]["backlash_unit_u95_deg"] = 1.4
    device = device_model_from_mapping(data)
    assert device_options(None, device)[1].unit_part == UnitPart(0.9, 1.4)
    assert device_options(None, device)[0].unit_part is None
    assert device_model_from_mapping(device_model_to_mapping(device)) == device
    assert dataclasses.replace(device.knobs[1], backlash_unit_u95_deg=None) != device.knobs[1]


def test_a_negative_part_is_refused_naming_the_key() -> None:
    data = yaml.safe_load(DEVICE.read_text())
    data["knobs"]["phi1"]["backlash_unit_u95_deg"] = -1.0
    with pytest.raises(ProfileError, match=r"knobs.phi1.backlash_unit_u95_deg"):
        device_model_from_mapping(data)


@pytest.mark.parametrize("extra, message", [
    (["--from-recording", "x.csv", "--unit-sample", "201"], "--unit-sample goes with --plant"),
    (["--plant", "simrig.plants.capstan:make_tendon_sheath_plant", "--unit-sample", "2x"],
     "--unit-sample: not a comma-separated list")])
def test_a_bad_sample_is_one_line(extra: list[str], message: str, tmp_path: Path,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["datasheet", "--device-model", "x", "--out", str(tmp_path / "d.yaml"), *extra])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "d.yaml").exists()


def test_the_part_moves_no_value_and_no_gate_half_width() -> None:
    (before,) = point_estimates([_sweep()])
    (after,) = point_estimates([with_unit_part(_sweep(), UnitPart(0.8, 1.5))])
    for name, e in before.items():
        assert (after[name].value, after[name].u95_deg, after[name].n) == pytest.approx(
            (e.value, e.u95_deg, e.n), nan_ok=True)
