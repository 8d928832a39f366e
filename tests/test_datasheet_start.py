"""`tsmd datasheet --start calibrated`: the sheet unit's sweeps run on the state a calibration
leaves (warm, soaked, as every scored unit is tracked), not on a fresh unit; with ``--update
FILE --sweep-constants`` only the fields those sweeps give move."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from support.profiles import ROOT

from tsmd.carried_plant import CarriedPlant
from tsmd.cli import main
from tsmd.config import default_sim_config
from tsmd.datasheet import KnobConstants
from tsmd.datasheet_start import sheet_unit_factory, with_sweep_constants
from tsmd.profile import DeviceModel, ReferencePoint, load_device_model
from tsmd.profile.device import DeviceKnob

LUMPED = ROOT / "profiles" / "devices" / "family" / "lumped.yaml"
PLANT = ["--plant", "simrig.family:make_family_plant", "--params", '{"plant":"lumped","unit":0}']
WARM_TIP_DEG = 3.0
"""How much further the fake calibrated unit's tip reaches at +-90 deg (warmgear's unit 0 read
2.99-3.03 deg more once calibrated, session 28)."""


class _Clock:
    """A plant whose only state is its clock; a reset takes it back to a fresh unit."""

    def __init__(self) -> None:
        self.t_s = 0.0

    def reset(self) -> None:
        self.t_s = 0.0

    def step(self, dt_s: float, knob_deg: Any) -> float:
        self.t_s += dt_s
        return self.t_s


def _calibrating(seen: list[int]) -> Callable[..., tuple[None, Any]]:
    def calibrate(device: DeviceModel, make: Callable[[], Any], seed: int,
                  config: Any = None) -> tuple[None, Any]:
        seen.append(seed)
        plant = make()
        plant.reset()
        plant.step(300.0, (0.0, 0.0))  # the calibration's five minutes
        return None, plant
    return calibrate


def test_a_fresh_start_sweeps_the_unit_as_built(monkeypatch: pytest.MonkeyPatch) -> None:
    seen: list[int] = []
    monkeypatch.setattr("tsmd.datasheet_start.calibrate_with_plant", _calibrating(seen))
    sheet = load_device_model(LUMPED)
    assert sheet_unit_factory("fresh", _Clock, sheet, 2000, default_sim_config()) is _Clock
    assert seen == []


def test_a_calibrated_start_sweeps_copies_that_go_on_from_the_calibration(
        monkeypatch: pytest.MonkeyPatch) -> None:
    seen: list[int] = []
    monkeypatch.setattr("tsmd.datasheet_start.calibrate_with_plant", _calibrating(seen))
    make = sheet_unit_factory("calibrated", _Clock, load_device_model(LUMPED), 2000,
                              default_sim_config(), log=lambda _: None)
    first, second = make(), make()
    assert seen == [2000]  # one calibration serves every sweep
    assert isinstance(first, CarriedPlant) and first.plant is not second.plant
    first.reset()  # the rig's reset at the start of a run keeps the inserted unit's state
    assert first.step(1.0, (0.0, 0.0)) == 301.0
    assert second.t_s == 300.0  # each sweep its own copy: the order of sweeps does not matter


def test_an_unknown_start_is_refused() -> None:
    with pytest.raises(ValueError, match="start must be one of"):
        sheet_unit_factory("warm", _Clock, load_device_model(LUMPED), 2000, default_sim_config())


def test_only_the_sweep_fields_the_sheet_carries_move() -> None:
    sheet = load_device_model(LUMPED)
    k = sheet.knobs[0]
    measured_knob = dataclasses.replace(
        k, omega=k.omega + 0.02, reference_pos=ReferencePoint(90.0, k.reference_pos.tip_deg + 3),
        handle_slip_deg=k.handle_slip_deg + 1.0, reference_backlash_gain=None,
        torque_ripple_period_deg=7.0)
    measured = dataclasses.replace(sheet, knobs=(measured_knob, sheet.knobs[1]))
    updated, lines = with_sweep_constants(sheet, measured)
    new = updated.knobs[0]
    assert new.omega == k.omega + 0.02
    assert new.reference_pos.tip_deg == k.reference_pos.tip_deg + 3
    assert new.handle_slip_deg == k.handle_slip_deg  # a design constant, not a sweep's
    assert new.torque_ripple_period_deg == k.torque_ripple_period_deg
    assert updated.knobs[1] == sheet.knobs[1]
    assert any(line.startswith("phi1.omega:") for line in lines)
    if k.reference_backlash_gain is not None:  # unread on the new sweep: kept and said so
        assert new.reference_backlash_gain == k.reference_backlash_gain
        assert any("reference_backlash_gain: not read" in line for line in lines)


def test_a_field_the_sheet_left_out_stays_out() -> None:
    sheet = load_device_model(LUMPED)
    bare = dataclasses.replace(sheet, knobs=(
        dataclasses.replace(sheet.knobs[0], release_omega=None), sheet.knobs[1]))
    measured = dataclasses.replace(sheet, knobs=(
        dataclasses.replace(sheet.knobs[0], release_omega=1.5), sheet.knobs[1]))
    updated, _ = with_sweep_constants(bare, measured)
    assert updated.knobs[0].release_omega is None


def _constants(knob: DeviceKnob, warm: bool) -> KnobConstants:
    shift = WARM_TIP_DEG if warm else 0.0
    return KnobConstants(
        omega=knob.omega, release_omega=knob.release_omega or knob.omega,
        reference_pos=ReferencePoint(90.0, knob.reference_pos.tip_deg + shift),
        reference_neg=ReferencePoint(-90.0, knob.reference_neg.tip_deg - shift),
        reference_backlash_pos_deg=knob.reference_backlash_pos_deg or 0.0,
        reference_backlash_neg_deg=knob.reference_backlash_neg_deg or 0.0,
        dead_zone_offset_deg=knob.dead_zone_offset_deg or 0.0,
        dead_zone_pos_deg=knob.reference_dead_zone_pos_deg,
        dead_zone_neg_deg=knob.reference_dead_zone_neg_deg,
        backlash_gain=knob.reference_backlash_gain,
        backlash_settle_fraction=knob.backlash_settle_fraction,
        backlash_release_slope_ratio=knob.backlash_release_slope_ratio,
        release_swing_A=knob.reference_release_swing_A, settle_lag_deg=knob.backlash_settle_lag_deg,
        release_line_share=knob.backlash_release_line_share,
        release_local_share=knob.backlash_release_local_share)


def _fake_sweeps(sheet: DeviceModel) -> Callable[..., list[KnobConstants]]:
    """The sheet's own constants, the reference tips 3 deg further on a calibrated unit."""
    def measure(factory: Callable[[], Any], *args: Any) -> list[KnobConstants]:
        warm = getattr(factory(), "calibrated_by_test", False)
        return [_constants(k, warm) for k in sheet.knobs]
    return measure


def _mark_calibrated(device: DeviceModel, make: Callable[[], Any], seed: int,
                     config: Any = None) -> tuple[None, Any]:
    plant = make()
    plant.calibrated_by_test = True
    return None, plant


def test_the_update_reads_the_reference_points_on_the_calibrated_unit(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    sheet = load_device_model(LUMPED)
    monkeypatch.setattr("tsmd.commands.datasheet_sweep.measure_device_constants",
                        _fake_sweeps(sheet))
    monkeypatch.setattr("tsmd.datasheet_start.calibrate_with_plant", _mark_calibrated)
    out = tmp_path / "warm.yaml"
    assert main(["datasheet", "--update", str(LUMPED), *PLANT, "--sweep-constants", "--start",
                 "calibrated", "--out", str(out)]) == 0
    after = load_device_model(out)
    for old, new in zip(sheet.knobs, after.knobs, strict=True):
        assert new.reference_pos.tip_deg == pytest.approx(old.reference_pos.tip_deg + 3.0)
        assert new.reference_neg.tip_deg == pytest.approx(old.reference_neg.tip_deg - 3.0)
        assert dataclasses.replace(new, reference_pos=old.reference_pos,
                                   reference_neg=old.reference_neg) == old
    assert "--sweep-constants --start calibrated --seed 2000" in out.read_text()


def test_the_update_on_a_fresh_start_gives_the_sheet_back(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    sheet = load_device_model(LUMPED)
    monkeypatch.setattr("tsmd.commands.datasheet_sweep.measure_device_constants",
                        _fake_sweeps(sheet))
    monkeypatch.setattr("tsmd.datasheet_start.calibrate_with_plant", _mark_calibrated)
    out = tmp_path / "cold.yaml"
    assert main(["datasheet", "--update", str(LUMPED), *PLANT, "--sweep-constants",
                 "--out", str(out)]) == 0
    assert load_device_model(out) == sheet


def test_a_calibrated_start_on_an_update_needs_the_sweeps_or_the_loop(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["datasheet", "--update", str(LUMPED), *PLANT, "--unit-edges", "--start",
                 "calibrated", "--out", str(tmp_path / "d.yaml")]) == 2
    assert "give --sweep-constants or --plateau-gap" in capsys.readouterr().err
    assert not (tmp_path / "d.yaml").exists()


def test_the_loop_on_an_update_plays_on_the_calibrated_unit(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    played_on: list[Any] = []

    def loop(device: DeviceModel, config: Any, factory: Callable[[], Any],
             seed: int) -> DeviceModel:
        played_on.append(factory())
        return device

    monkeypatch.setattr("tsmd.datasheet_start.calibrate_with_plant", _mark_calibrated)
    monkeypatch.setattr("tsmd.commands.datasheet_update.with_plateau_gap", loop)
    out = tmp_path / "loop.yaml"
    assert main(["datasheet", "--update", str(LUMPED), *PLANT, "--plateau-gap", "--start",
                 "calibrated", "--out", str(out)]) == 0
    assert [getattr(p, "calibrated_by_test", False) for p in played_on] == [True]
    assert "--plateau-gap --start calibrated" in out.read_text()


def test_the_sweep_constants_go_with_an_update(tmp_path: Path,
                                                capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["datasheet", *PLANT, "--device-model", "x", "--sweep-constants", "--out",
                 str(tmp_path / "d.yaml")]) == 2
    assert "--sweep-constants goes with --update" in capsys.readouterr().err


def test_a_full_measurement_sweeps_again_after_a_calibration_under_its_fresh_sheet(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    sheet = load_device_model(LUMPED)
    calibrated_under: list[DeviceModel] = []
    coupled_on: list[Any] = []

    def calibrate(device: DeviceModel, make: Callable[[], Any], seed: int,
                  config: Any = None) -> tuple[None, Any]:
        calibrated_under.append(device)
        return _mark_calibrated(device, make, seed, config)

    def coupling(device: DeviceModel, config: Any, factory: Callable[[], Any],
                 seed: int) -> DeviceModel:
        coupled_on.append(factory())
        return device

    monkeypatch.setattr("tsmd.commands.datasheet.measure_device_constants", _fake_sweeps(sheet))
    monkeypatch.setattr("tsmd.datasheet_start.calibrate_with_plant", calibrate)
    monkeypatch.setattr("tsmd.commands.datasheet.with_coupling", coupling)
    out = tmp_path / "full.yaml"
    assert main(["datasheet", *PLANT, "--device-model", "family-lumped", "--start",
                 "calibrated", "--rule-seeds", "none", "--no-ratio-gain", "--out",
                 str(out)]) == 0
    cold, warm = sheet.knobs[0].reference_pos.tip_deg, load_device_model(out).knobs[0]
    assert [d.knobs[0].reference_pos.tip_deg for d in calibrated_under] == [cold]
    assert warm.reference_pos.tip_deg == pytest.approx(cold + WARM_TIP_DEG)
    assert [isinstance(p, CarriedPlant) for p in coupled_on] == [True]  # a sweep stage
    assert "start calibrated" in out.read_text()
