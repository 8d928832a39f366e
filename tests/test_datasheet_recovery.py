"""The recovery rule's sheet constants: the lag from the half-cycles that show the recovery, the
bend gain from the tip against the swing law, kept only where the rule is chosen."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
from support.profiles import DEVICE as DEVICE_PATH

from tsmd.calibration.recovery import expected_backlash_deg
from tsmd.calibration.sweep_result import HalfCycle, SweepResult
from tsmd.cli import main
from tsmd.datasheet_recovery import (
    bend_gains,
    probe_sheet,
    recovery_lags,
    recovery_where_chosen,
)
from tsmd.datasheet_rule import usable
from tsmd.profile import DeviceModel, load_device_model

DEVICE = load_device_model(DEVICE_PATH)
GRID = (-90.0, 0.0, 90.0)


def point(knob: int, other: float, unseen: tuple[str, ...] = (),
          swing_A: float = 0.1, **values: tuple[float, ...]) -> Any:
    """A grid point whose half-cycles after a reversal swing ``swing_A`` on both sides."""
    halves = tuple(HalfCycle(d, 0, 1, True, release_swing_A=swing_A) for d in (1, -1))
    result = SweepResult(None, halves, dict(values),  # type: ignore[arg-type]
                         unseen={n: 1.0 for n in unseen})
    return SimpleNamespace(knob=knob, other_deg=other, result=result)


def sheet(swing_A: float = 0.1, ref_deg: float = 8.0) -> DeviceModel:
    knobs = tuple(dataclasses.replace(k, reference_backlash_pos_deg=ref_deg,
                                      reference_backlash_neg_deg=ref_deg,
                                      reference_release_swing_A=swing_A) for k in DEVICE.knobs)
    return dataclasses.replace(DEVICE, knobs=(knobs[0], knobs[1]))


def test_the_lag_is_the_median_tip_minus_end_over_the_half_cycles_that_show_it() -> None:
    runs: Any = [SimpleNamespace(points=[
        point(0, 0.0, backlash_pos_deg=(12.0, 13.0, 14.0), backlash_neg_deg=(13.0,)),
        point(1, 0.0, backlash_pos_deg=(7.0,), backlash_neg_deg=(8.0,))])]
    truth = {(k, 0.0): {"backlash_pos_deg": 10.0, "backlash_neg_deg": 10.0} for k in (0, 1)}
    assert recovery_lags(runs, truth) == (pytest.approx(-3.0), pytest.approx(2.5))


def test_the_sheets_fallback_values_are_no_readings_of_the_lag() -> None:
    runs: Any = [SimpleNamespace(points=[
        point(0, 0.0, backlash_pos_deg=(13.0,), backlash_neg_deg=(30.0, 30.0, 30.0),
              unseen=("backlash_neg_deg",)),
        point(1, 0.0, unseen=("backlash_pos_deg",), backlash_pos_deg=(20.0,))])]
    truth = {(k, 0.0): {"backlash_pos_deg": 10.0, "backlash_neg_deg": 10.0} for k in (0, 1)}
    assert recovery_lags(runs, truth) == (pytest.approx(-3.0), None)


def test_the_bend_gain_is_the_tips_backlash_at_90_over_the_swing_laws_against_0() -> None:
    # at +-90 the tip's B is 1.2 x what the swing law gives, at 0 exactly the law
    swings = {-90.0: 0.12, 0.0: 0.1, 90.0: 0.11}
    runs: Any = [SimpleNamespace(points=[point(k, a, swing_A=s) for k in (0, 1)
                                         for a, s in swings.items()])]
    law = {a: expected_backlash_deg(8.0, s, 0.1) for a, s in swings.items()}
    truth = {(k, a): {"backlash_pos_deg": law[a] * (1.2 if a else 1.0),
                      "backlash_neg_deg": law[a] * (1.2 if a else 1.0)}
             for k in (0, 1) for a in GRID}
    assert bend_gains(runs, truth, sheet()) == (pytest.approx(1.2), pytest.approx(1.2))


def test_no_bend_gain_without_a_sweep_at_the_other_knobs_0() -> None:
    runs: Any = [SimpleNamespace(points=[point(0, 90.0), point(1, 90.0)])]
    truth = {(k, 90.0): {"backlash_pos_deg": 9.0, "backlash_neg_deg": 9.0} for k in (0, 1)}
    assert bend_gains(runs, truth, sheet()) == (None, None)


def test_the_probe_calibrates_every_knob_under_the_recovery_rule_without_a_lag() -> None:
    probe = probe_sheet(DEVICE)
    assert all(usable(k, "recovery") and k.backlash_release_rule == "recovery"
               and k.backlash_recovery_lag_deg == 0.0 and k.reading_offset is None
               for k in probe.knobs)


def test_a_knob_choosing_another_rule_keeps_no_recovery_constants() -> None:
    k = dataclasses.replace(DEVICE.knobs[0], backlash_recovery_lag_deg=-3.3,
                            backlash_bend_gain=1.2)
    device = dataclasses.replace(DEVICE, knobs=(
        dataclasses.replace(k, backlash_release_rule="recovery"),
        dataclasses.replace(k, backlash_release_rule="line")))
    kept = recovery_where_chosen(device)
    assert (kept.knobs[0].backlash_recovery_lag_deg, kept.knobs[0].backlash_bend_gain) == (-3.3,
                                                                                           1.2)
    assert (kept.knobs[1].backlash_recovery_lag_deg, kept.knobs[1].backlash_bend_gain) == (None,
                                                                                           None)


def test_the_recovery_rule_without_a_rule_choice_is_one_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["datasheet", "--plant", "simrig.plants.capstan:make_tendon_sheath_plant",
                 "--device-model", "x", "--out", str(tmp_path / "d.yaml"),
                 "--rule-seeds", "none", "--recovery-rule"])
    assert code == 2
    assert "--recovery-rule" in capsys.readouterr().err
    assert not (tmp_path / "d.yaml").exists()
