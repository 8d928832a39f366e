"""The online benchmark's own pieces (the runs themselves are `tsmd bench online`)."""

from __future__ import annotations

import argparse

import numpy as np
import pytest

from simrig.family import PLANT_SPECS
from simrig.scenario import ShapeChange
from tsmd.bench import online
from tsmd.bench.online import add_arguments, mixed_motion, reversal_times, shape_change
from tsmd.bench.online_units import make_unit
from tsmd.calibration.errors import CalibrationRefusedError
from tsmd.errors import TsmdError


def test_shape_changes_are_named_slack_or_curvature() -> None:
    assert shape_change("slack:0.5") == {"slack_delta_mm": ((0.5, 0.5), (0.5, 0.5))}
    assert shape_change("curvature:90") == {"sheath_curvature_deg": 90.0}


@pytest.mark.parametrize("bad", ["slack", "bend:3", "curvature:x"])
def test_a_bad_shape_change_is_one_line(bad: str) -> None:
    with pytest.raises(TsmdError, match="expected slack:MM or curvature:DEG"):
        shape_change(bad)


def test_reversals_are_counted_after_the_given_time() -> None:
    t = np.arange(0.0, 40.0, 0.004)
    q = 60.0 * np.sin(2 * np.pi * 0.05 * t)  # turns at 5, 15, 25, 35 s
    assert np.allclose(reversal_times(t, q, 10.0), [15.0, 25.0, 35.0], atol=0.01)


def test_mixed_motion_stays_inside_the_knob_range_and_starts_at_rest() -> None:
    t, q = mixed_motion(120.0, 3)
    assert np.all(np.abs(q) <= 60.0) and np.allclose(q[0], 0.0)
    assert len(reversal_times(t, q[:, 0], 0.0)) >= 20


def _all_refused(monkeypatch: pytest.MonkeyPatch) -> int:
    def refused(unit: int, *_: object) -> dict[str, object]:
        raise CalibrationRefusedError(f"calibration refused (unit {unit}): too uncertain", [])

    monkeypatch.setattr(online, "device_for", lambda *_: None)
    monkeypatch.setattr(online, "hot_path_us", lambda: (1.0, 2.0, 3.0))
    monkeypatch.setattr(online, "change_unit", refused)
    monkeypatch.setattr(online, "drift_unit", refused)
    parser = argparse.ArgumentParser()
    online.add_arguments(parser)
    return online.main(parser.parse_args(["--units", "7,8", "--drift-s", "10"]))


def test_a_unit_whose_calibration_is_refused_is_one_line_and_the_bench_goes_on(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    _all_refused(monkeypatch)
    lines = [ln for ln in capsys.readouterr().out.splitlines()
             if ln.startswith("| ") and "refused" in ln]
    assert len(lines) == 4 and "| 7 |" in lines[0] and "| 8 |" in lines[1]


def test_a_bench_that_scored_no_unit_says_so_and_fails(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    assert _all_refused(monkeypatch) == 1
    assert "no unit scored" in capsys.readouterr().out


@pytest.mark.parametrize("plant", sorted(PLANT_SPECS))
def test_every_family_plant_is_a_choice_and_takes_both_shape_changes(plant: str) -> None:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    assert parser.parse_args(["--plant", plant]).plant == plant
    for kind in ("slack:0.5", "curvature:90"):
        unit = make_unit(plant, 101, [ShapeChange(0.0, shape_change(kind))])
        assert np.all(np.isfinite(unit.step(0.004, np.array([10.0, -10.0])).tip_deg))
