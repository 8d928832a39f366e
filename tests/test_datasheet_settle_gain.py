"""The settle-gain reading checked on the data sheet's own unit (`tsmd.datasheet_settle_gain`)
and a sheet whose units take no settle reading."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import pytest
from test_compensation_tension_play_fit import DEVICE_KNOB, synthetic_sweep

import tsmd.datasheet_settle_gain as settle_gain
from tsmd.calibration.tension_play_fit import fit_tension_play
from tsmd.calibration.unit_slope import GainReading
from tsmd.profile import DeviceModel


def _runs(monkeypatch: pytest.MonkeyPatch, unit_gain: float, sd: float) -> list[SimpleNamespace]:
    reading = GainReading(0.133, unit_gain, sd)
    monkeypatch.setattr(settle_gain, "settle_reading", lambda points, knob, gain: reading)
    return [SimpleNamespace(points=[object()]), SimpleNamespace(points=[object()])]


def test_a_settle_reading_that_gives_its_own_unit_its_slope_is_kept(
        monkeypatch: pytest.MonkeyPatch) -> None:
    runs = _runs(monkeypatch, 0.135, 0.02)
    check = settle_gain.settle_check(runs, 0, 0.133)  # type: ignore[arg-type]
    assert check.kept and check.readings == 2


def test_a_settle_reading_that_moves_its_own_units_slope_beyond_its_half_width_is_dropped(
        monkeypatch: pytest.MonkeyPatch) -> None:
    runs = _runs(monkeypatch, 0.211, 0.02)  # notchclutch unit 0's phi2, session 24: ratio 0.91
    check = settle_gain.settle_check(runs, 1, 0.137)  # type: ignore[arg-type]
    assert not check.kept
    assert check.ratio == pytest.approx((1 - 0.211) / (1 - 0.133))


def test_the_check_marks_only_the_knob_whose_reading_fails(
        monkeypatch: pytest.MonkeyPatch) -> None:
    runs = _runs(monkeypatch, 0.211, 0.02)
    knob = dataclasses.replace(DEVICE_KNOB, reference_backlash_gain=0.133)
    device = DeviceModel("x", (knob, dataclasses.replace(knob, reference_backlash_gain=None)))
    checked, checks = settle_gain.with_settle_check(device, runs)  # type: ignore[arg-type]
    assert [k.settle_gain_read for k in checked.knobs] == [False, None]
    assert checks[1].kept and not checks[0].kept


def test_a_sheet_whose_unit_fails_the_check_gives_omega_without_the_settle_reading() -> None:
    grid = (-90.0, 0.0, 90.0)
    knob = dataclasses.replace(DEVICE_KNOB, reference_backlash_gain=0.2)
    sweeps = [dataclasses.replace(synthetic_sweep(g, backlash_deg=15.0),
                                  settle_backlash_deg=(30.0, 30.0)) for g in grid]
    read = fit_tension_play(sweeps, knob)
    unread = fit_tension_play(sweeps, dataclasses.replace(knob, settle_gain_read=False))
    assert unread.omega == pytest.approx(DEVICE_KNOB.omega)
    assert read.omega != pytest.approx(DEVICE_KNOB.omega, abs=0.01)
