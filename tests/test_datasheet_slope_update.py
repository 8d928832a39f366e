"""`tsmd datasheet --update FILE --slope-sample LIST / --release-round`: the sample's slope
weight and the sheet unit's rounded release added to an existing sheet, nothing else changed."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import pytest
from support.profiles import ROOT

from tsmd.cli import main
from tsmd.datasheet_slope_weight import SlopePair
from tsmd.profile import DeviceModel, load_device_model

WORM = ROOT / "profiles" / "devices" / "family" / "wormeyelet.yaml"
PLANT = ["--plant", "simrig.family:make_family_plant", "--params",
         '{"plant":"wormeyelet","unit":0}', "--unit-key", "unit"]


def _pairs(device: DeviceModel, config: Any, unit: str, make: Any, seed: int
           ) -> tuple[SlopePair, SlopePair]:
    move = {"0": 0.0, "201": 0.04, "202": -0.05}[unit]
    return SlopePair(unit, 1 + move, 1 + 0.5 * move), SlopePair(unit, 1.0, 1 + move)


def _rounded_phi1(device: DeviceModel, *args: Any) -> DeviceModel:
    return dataclasses.replace(device, knobs=(
        dataclasses.replace(device.knobs[0], release_shift=0.1, release_round=0.4),
        device.knobs[1]))


def test_the_samples_weight_is_added_with_nothing_else_changed(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("tsmd.commands.datasheet_sample.sample_pairs", _pairs)
    out = tmp_path / "new.yaml"
    assert main(["datasheet", "--update", str(WORM), *PLANT, "--slope-sample", "201,202",
                 "--out", str(out)]) == 0
    before, after = load_device_model(WORM), load_device_model(out)
    assert after.knobs[0].slope_gain_weight == pytest.approx(0.5)
    assert after.knobs[1].slope_gain_weight is None  # its readings did not move
    assert dataclasses.replace(after, knobs=tuple(  # type: ignore[arg-type]
        dataclasses.replace(k, slope_gain_weight=None) for k in after.knobs)) == before
    assert "--slope-sample 201,202" in out.read_text()


def test_a_scored_unit_is_never_in_the_slope_sample(tmp_path: Path,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["datasheet", "--update", str(WORM), *PLANT, "--slope-sample", "101",
                 "--out", str(tmp_path / "d.yaml")]) == 2
    assert "scored" in capsys.readouterr().err


def test_the_rounded_release_is_added_to_a_sheet_with_nothing_else_changed(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("tsmd.commands.datasheet_update.with_release_round", _rounded_phi1)
    out = tmp_path / "new.yaml"
    assert main(["datasheet", "--update", str(WORM), *PLANT, "--release-round",
                 "--out", str(out)]) == 0
    assert load_device_model(out) == _rounded_phi1(load_device_model(WORM))


def test_the_slope_sample_goes_with_update(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["datasheet", "--device-model", "x", *PLANT, "--slope-sample", "201",
                 "--out", str(tmp_path / "d.yaml")]) == 2
    assert "--slope-sample goes with --update" in capsys.readouterr().err
