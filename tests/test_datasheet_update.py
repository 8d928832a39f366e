"""`tsmd datasheet --update`: the sample's part added to an existing sheet, nothing else of it
changed (docs/calibration.md, session 20)."""

from __future__ import annotations

import argparse
import dataclasses
import difflib
import shutil
from pathlib import Path

import pytest
from support.profiles import ROOT

from tsmd.cli import main
from tsmd.commands.datasheet_args import add_arguments
from tsmd.commands.datasheet_sample import sample_units
from tsmd.commands.datasheet_update import UPDATE_STAGES
from tsmd.compensation.level_grid import LevelGrid
from tsmd.datasheet import DatasheetError
from tsmd.datasheet_sample import SAMPLE_KEYS, Readings
from tsmd.profile import DeviceModel, ProfileError, load_device_model, save_device_fields

LUMPED = ROOT / "profiles" / "devices" / "family" / "lumped.yaml"
PLANT = ["--plant", "simrig.family:make_family_plant", "--params", '{"plant":"lumped","unit":0}']


def _with_parts(device: DeviceModel) -> DeviceModel:
    knobs = tuple(dataclasses.replace(k, dead_zone_unit_u95_deg=0.8 + i,
                                      backlash_unit_u95_deg=None if i else 1.25)
                  for i, k in enumerate(device.knobs))
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


@pytest.fixture
def bare(tmp_path: Path) -> Path:
    """Lumped's shipped sheet without a sample's part (its other lines as shipped)."""
    path = tmp_path / "bare.yaml"
    path.write_text("".join(line for line in LUMPED.read_text().splitlines(True)
                            if "unit_u95_deg" not in line))
    return path


def _changed(before: Path, after: Path) -> list[str]:
    return [line for line in difflib.unified_diff(before.read_text().splitlines(),
                                                  after.read_text().splitlines(), n=0)
            if line[:1] in "+-" and line[:3] not in ("+++", "---")]


def test_units_and_ranges_make_one_sample() -> None:
    assert sample_units("201-203, 205", 0) == [201, 202, 203, 205]


@pytest.mark.parametrize("text", ["1", "201,108", "100-101"])
def test_a_scored_unit_is_never_in_the_sample(text: str) -> None:
    with pytest.raises(DatasheetError, match="scored"):
        sample_units(text, 0)


@pytest.mark.parametrize("text", ["201,201", "0,201"])
def test_a_unit_twice_is_refused(text: str) -> None:
    with pytest.raises(DatasheetError, match="twice"):
        sample_units(text, 0)


def test_only_the_sample_fields_and_the_header_change(bare: Path, tmp_path: Path) -> None:
    out = tmp_path / "new.yaml"
    save_device_fields(bare, _with_parts(load_device_model(bare)), SAMPLE_KEYS, out,
                       "the part, added")
    changed = _changed(bare, out)
    assert changed == ["+# the part, added", "+    dead_zone_unit_u95_deg: 0.8",
                       "+    backlash_unit_u95_deg: 1.25", "+    dead_zone_unit_u95_deg: 1.8"]
    assert load_device_model(out) == _with_parts(load_device_model(bare))


def test_a_part_written_again_replaces_its_lines(bare: Path, tmp_path: Path) -> None:
    once, twice = tmp_path / "once.yaml", tmp_path / "twice.yaml"
    device = _with_parts(load_device_model(bare))
    save_device_fields(bare, device, SAMPLE_KEYS, once, "")
    save_device_fields(once, device, SAMPLE_KEYS, twice, "")
    assert twice.read_text() == once.read_text()


def test_a_change_beyond_the_fields_is_not_written(tmp_path: Path) -> None:
    device = load_device_model(LUMPED)
    moved = dataclasses.replace(device, knobs=(dataclasses.replace(device.knobs[0], omega=1.0),
                                               device.knobs[1]))
    with pytest.raises(ProfileError, match="would change"):
        save_device_fields(LUMPED, moved, SAMPLE_KEYS, tmp_path / "new.yaml", "")
    assert not (tmp_path / "new.yaml").exists()


def test_update_calibrates_the_sample_under_the_sheet_and_writes_only_its_part(
        bare: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    sheet = tmp_path / "lumped.yaml"
    shutil.copy(bare, sheet)
    seen: list[tuple[DeviceModel, list[object]]] = []

    def fake(device: DeviceModel, configs: list[object], seed: int
             ) -> tuple[DeviceModel, list[Readings]]:
        seen.append((device, [c.sim.params for c in configs]))  # type: ignore[attr-defined]
        one: Readings = {(k, kind): ([0.5], [0.2]) for k in (0, 1)
                         for kind in ("dead-zone edge", "backlash")}
        return _with_parts(device), [one] * len(configs)

    monkeypatch.setattr("tsmd.commands.datasheet_sample.measure_sample", fake)
    out = tmp_path / "new.yaml"
    assert main(["datasheet", "--update", str(sheet), *PLANT, "--unit-sample", "201-202",
                 "--out", str(out)]) == 0
    assert seen[0][0] == load_device_model(bare)
    assert [p["unit"] for p in seen[0][1]] == [0, 201, 202]  # type: ignore[index]
    assert sheet.read_text() == bare.read_text()
    changed = _changed(bare, out)
    assert all(line.startswith("+#") or line.split(":")[0].strip("+ ") in SAMPLE_KEYS
               for line in changed)
    assert any("--unit-sample 201-202" in line for line in changed)


@pytest.mark.parametrize("extra, message", [
    (["--unit-sample", "201", "--update", "/no/such.yaml"], "no such file"),
    (["--unit-sample", "101", "--update", str(LUMPED)], "scored"),
    (["--unit-sample", "201", "--update", str(LUMPED), "--loaded-shape"], "anew"),
    (["--update", str(LUMPED)], "--update adds the sweep constants, the stick end")])
def test_a_bad_update_is_one_line_and_writes_nothing(
        extra: list[str], message: str, tmp_path: Path,
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["datasheet", *PLANT, "--out", str(tmp_path / "d.yaml"), *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "d.yaml").exists()


def test_a_sample_of_another_product_is_refused(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["datasheet", "--plant", "simrig.family:make_family_plant", "--params",
                 '{"plant":"coilpipe","unit":0}', "--update", str(LUMPED), "--unit-sample",
                 "201", "--out", str(tmp_path / "d.yaml")]) == 2
    assert "its sample must be units of its product" in capsys.readouterr().err


def test_update_with_the_plateau_gap_writes_only_the_loops_fields(
        bare: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def fake(device: DeviceModel, config: object, factory: object, seed: int) -> DeviceModel:
        knobs = tuple(dataclasses.replace(k, plateau_gap_deg=8.5 + i, plateau_gap_factor=1.3)
                      for i, k in enumerate(device.knobs))
        return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))

    monkeypatch.setattr("tsmd.commands.datasheet_update.with_plateau_gap", fake)
    out = tmp_path / "new.yaml"
    assert main(["datasheet", "--update", str(bare), *PLANT, "--plateau-gap",
                 "--out", str(out)]) == 0
    changed = _changed(bare, out)
    assert [line for line in changed if not line.startswith("+#")] == [
        "+    plateau_gap_deg: 8.5", "+    plateau_gap_factor: 1.3",
        "+    plateau_gap_deg: 9.5", "+    plateau_gap_factor: 1.3"]
    assert any("--plateau-gap" in line for line in changed)


def test_update_with_the_level_grid_adds_the_grid_read_under_the_sheet(
        bare: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    seen: list[DeviceModel] = []

    def fake(device: DeviceModel, config: object, factory: object, seed: int) -> DeviceModel:
        seen.append(device)
        grid = LevelGrid((0.0, 60.0), (0.0, -6.5), (0.0, 5.0))
        knobs = tuple(dataclasses.replace(k, loaded_level_grid=grid) for k in device.knobs)
        return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))

    monkeypatch.setattr("tsmd.commands.datasheet_update.with_level_grid", fake)
    out = tmp_path / "new.yaml"
    assert main(["datasheet", "--update", str(bare), *PLANT, "--level-grid",
                 "--out", str(out)]) == 0
    before, after = load_device_model(bare), load_device_model(out)
    assert seen == [before]
    assert after == fake(before, None, None, 0)
    assert "--level-grid" in out.read_text().split("schema_version")[0]


def test_update_with_the_home_hold_adds_the_choice_made_under_the_sheet(
        bare: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    seen: list[DeviceModel] = []

    def fake(device: DeviceModel, config: object, factory: object, seed: int) -> DeviceModel:
        seen.append(device)
        return device.with_knob_flag("hold_at_home", (True, False))

    monkeypatch.setattr("tsmd.commands.datasheet_update.with_home_hold", fake)
    out = tmp_path / "new.yaml"
    assert main(["datasheet", "--update", str(bare), *PLANT, "--home-hold",
                 "--out", str(out)]) == 0
    before, after = load_device_model(bare), load_device_model(out)
    assert seen == [before]
    assert after == fake(before, None, None, 0)
    assert [k.hold_at_home for k in after.knobs] == [True, None]
    assert "--home-hold" in out.read_text().split("schema_version")[0]


def test_every_update_stage_is_an_option_of_the_command() -> None:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    dests = {a.dest for a in parser._actions}
    assert [s.option for s in UPDATE_STAGES if s.option not in dests] == []


def test_update_stages_write_disjoint_fields() -> None:
    fields = [f for s in UPDATE_STAGES for f in s.fields]
    assert len(fields) == len(set(fields))
