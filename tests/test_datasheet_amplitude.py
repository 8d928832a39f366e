"""The tip's backlash growth on the data sheet's unit, read at the 1 deg threshold or at the
corners of the paper's lines, and the sheet key each reading goes to (sessions 16-17)."""

from __future__ import annotations

from typing import Any

import pytest
from support.profiles import DEVICE

from tsmd import datasheet_amplitude
from tsmd.commands import datasheet_measure as datasheet_command
from tsmd.config import default_sim_config
from tsmd.profile import load_device_model


def _fake_gains(calls: list[str]) -> Any:
    def measure(_factory: Any, _seed: int, _config: Any, by: str = "threshold"
                ) -> tuple[float | None, float | None]:
        calls.append(by)
        return (0.165, None) if by == "lines" else (0.133, 0.145)
    return measure


def test_the_line_reading_goes_to_its_own_key(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[str] = []
    monkeypatch.setattr(datasheet_command, "measure_tip_backlash_gains", _fake_gains(calls))
    device = load_device_model(DEVICE)
    out = datasheet_command.with_tip_backlash_gain(device, default_sim_config(), object, 2000,
                                                    by="lines")
    assert calls == ["lines"]
    assert out.knobs[0].reference_tip_line_backlash_gain == 0.165
    assert out.knobs[1].reference_tip_line_backlash_gain is None
    assert [k.reference_tip_backlash_gain for k in out.knobs] == [
        k.reference_tip_backlash_gain for k in device.knobs]


def test_the_threshold_reading_keeps_its_key(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[str] = []
    monkeypatch.setattr(datasheet_command, "measure_tip_backlash_gains", _fake_gains(calls))
    out = datasheet_command.with_tip_backlash_gain(load_device_model(DEVICE),
                                                    default_sim_config(), object, 2000)
    assert calls == ["threshold"]
    assert [k.reference_tip_backlash_gain for k in out.knobs] == [0.133, 0.145]
    assert all(k.reference_tip_line_backlash_gain is None for k in out.knobs)


def test_the_measurement_reads_every_sweep_the_asked_way(monkeypatch: pytest.MonkeyPatch
                                                        ) -> None:
    readings: list[tuple[int, float, str]] = []

    def backlash(_factory: Any, knob: int, amplitude_deg: float, _seed: int, _config: Any,
                 by: str = "threshold") -> tuple[float, float]:
        readings.append((knob, amplitude_deg, by))
        return (0.17 * amplitude_deg, 0.17 * amplitude_deg)

    monkeypatch.setattr(datasheet_amplitude, "tip_backlash_deg", backlash)
    gains = datasheet_amplitude.measure_tip_backlash_gains(object, by="lines")
    assert gains == pytest.approx((0.17, 0.17))
    assert {r[2] for r in readings} == {"lines"}
    assert sorted((r[0], r[1]) for r in readings) == [(0, 60.0), (0, 90.0), (1, 60.0), (1, 90.0)]
