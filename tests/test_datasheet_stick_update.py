"""`tsmd datasheet --update FILE --stick-end / --settle-gain-check`: the choices made on the
sheet's unit added to an existing sheet, written whole with every other field as it was."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import pytest
from support.profiles import ROOT

from tsmd.cli import main
from tsmd.profile import DeviceModel, load_device_model

LUMPED = ROOT / "profiles" / "devices" / "family" / "lumped.yaml"
PLANT = ["--plant", "simrig.family:make_family_plant", "--params", '{"plant":"lumped","unit":0}']


def _stick_on_phi2(device: DeviceModel, *args: Any) -> DeviceModel:
    return dataclasses.replace(device, knobs=(
        device.knobs[0], dataclasses.replace(device.knobs[1], backlash_stick_end=True)))


def _settle_off_phi1(device: DeviceModel, *args: Any) -> DeviceModel:
    return dataclasses.replace(device, knobs=(
        dataclasses.replace(device.knobs[0], settle_gain_read=False), device.knobs[1]))


def test_the_stick_end_and_settle_check_are_added_with_nothing_else_changed(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr("tsmd.commands.datasheet_update.with_stick_choice", _stick_on_phi2)
    monkeypatch.setattr("tsmd.commands.datasheet_update.with_settle_gain_check",
                        _settle_off_phi1)
    out = tmp_path / "new.yaml"
    assert main(["datasheet", "--update", str(LUMPED), *PLANT, "--stick-end",
                 "--settle-gain-check", "--rule-seeds", "0,1", "--out", str(out)]) == 0
    before, after = load_device_model(LUMPED), load_device_model(out)
    assert after == _settle_off_phi1(_stick_on_phi2(before))
    text = out.read_text()
    assert "--stick-end --settle-gain-check --rule-seeds 0,1" in text
    assert text.startswith("".join(line for line in LUMPED.read_text().splitlines(True)
                                   if line.startswith("#"))[:40])


def test_the_stick_end_needs_rule_seeds(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["datasheet", "--update", str(LUMPED), *PLANT, "--stick-end", "--rule-seeds",
                 "none", "--out", str(tmp_path / "d.yaml")]) == 2
    assert "needs rule seeds" in capsys.readouterr().err
    assert not (tmp_path / "d.yaml").exists()
