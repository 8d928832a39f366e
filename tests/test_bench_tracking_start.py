"""Where a tracking scenario starts: the plant its unit's calibration left (warm, soaked), a fresh
plant after the conditioning cycle, or a fresh plant."""

from __future__ import annotations

import argparse
import pickle
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from simrig.family import family_member
from tsmd.bench import accuracy, family_accuracy, tracking_start
from tsmd.bench.tracking_start import (
    cached_unit,
    conditions,
    plant_path,
    scenario_plant,
    start_of,
)
from tsmd.carried_plant import CarriedPlant
from tsmd.config import resolve_data_path
from tsmd.profile import load_profile

EXAMPLE = resolve_data_path("profiles/example-sim.yaml")


def warmed_warmgear(seconds: float) -> Any:
    """Warmgear unit 1 left at rest for ``seconds`` of plant time (its shaft warms)."""
    plant = family_member("warmgear", 1).build()
    plant.reset()
    for _ in range(int(seconds)):
        plant.step(1.0, np.zeros(2))
    return plant


def parsed(module: Any, argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    module.add_arguments(parser)
    return parser.parse_args(argv)


@pytest.mark.parametrize("module", [family_accuracy, accuracy])
def test_the_tracking_benches_start_from_the_calibrated_plant_unless_asked(module: Any) -> None:
    assert start_of(parsed(module, [])) == "calibrated"
    assert start_of(parsed(module, ["--start", "conditioned"])) == "conditioned"
    assert start_of(parsed(module, ["--start", "fresh"])) == "fresh"


@pytest.mark.parametrize("module", [family_accuracy, accuracy])
def test_the_older_fresh_flag_still_asks_for_the_fresh_start(module: Any) -> None:
    assert start_of(parsed(module, ["--fresh"])) == "fresh"


def test_accuracy_hands_its_start_to_the_family_bench() -> None:
    args = family_accuracy.namespace_from(argparse.Namespace(start="conditioned", units="1"))
    assert start_of(args) == "conditioned"


def test_only_the_fresh_start_skips_the_conditioning_cycle() -> None:
    assert conditions("calibrated") and conditions("conditioned")
    assert not conditions("fresh")


def test_a_calibrated_start_runs_a_warm_copy_that_goes_on_from_the_calibrated_state() -> None:
    plant = warmed_warmgear(600.0)
    make = scenario_plant("calibrated", lambda: family_member("warmgear", 1).build(), plant)
    run = make()
    assert isinstance(run, CarriedPlant)
    run.reset()  # the rig's reset at the start of a run
    run.step(1.0, np.zeros(2))
    assert run.t_s == pytest.approx(601.0)
    assert run.temperature_C > 30.0
    assert plant.t_s == pytest.approx(600.0)  # the calibrated plant itself is not driven
    assert make().t_s == pytest.approx(600.0)  # every scenario gets its own copy


@pytest.mark.parametrize("start", ["conditioned", "fresh"])
def test_the_older_starts_build_the_unit_anew(start: str) -> None:
    make = scenario_plant(start, lambda: family_member("warmgear", 1).build(), None)
    run = make()
    run.reset()
    assert run.t_s == 0.0 and run.temperature_C == pytest.approx(22.0)


def test_a_calibrated_start_without_the_calibrated_plant_is_refused() -> None:
    with pytest.raises(ValueError, match="calibration left"):
        scenario_plant("calibrated", lambda: None, None)


def _no_calibration(*_: object, **__: object) -> None:
    raise AssertionError("calibrated again")


def test_a_cached_profile_and_plant_are_taken_without_calibrating(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(tracking_start, "calibrate_with_plant", _no_calibration)
    path = tmp_path / "unit-1.yaml"
    shutil.copy(EXAMPLE, path)
    with plant_path(path).open("wb") as f:
        pickle.dump(warmed_warmgear(5.0), f)
    profile, plant = cached_unit(path, None, lambda: None, True, lambda _: None)
    assert profile.catheter_id == load_profile(EXAMPLE).catheter_id
    assert plant.t_s == pytest.approx(5.0)


def test_a_cached_profile_serves_the_older_starts_without_its_plant(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(tracking_start, "calibrate_with_plant", _no_calibration)
    path = tmp_path / "unit-1.yaml"
    shutil.copy(EXAMPLE, path)
    _, plant = cached_unit(path, None, lambda: None, False, lambda _: None)
    assert plant is None


def test_a_cached_profile_without_its_plant_is_calibrated_again_and_the_plant_kept(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[int] = []

    def calibrate(*_: object) -> tuple[Any, Any]:
        calls.append(1)
        return load_profile(EXAMPLE), warmed_warmgear(3.0)

    monkeypatch.setattr(tracking_start, "calibrate_with_plant", calibrate)
    path = tmp_path / "unit-1.yaml"
    shutil.copy(EXAMPLE, path)
    _, plant = cached_unit(path, None, lambda: None, True, lambda _: None)
    assert calls == [1] and plant.t_s == pytest.approx(3.0)
    with plant_path(path).open("rb") as f:
        assert pickle.load(f).t_s == pytest.approx(3.0)


def test_the_family_bench_scores_every_scenario_on_a_copy_of_the_calibrated_plant(
        monkeypatch: pytest.MonkeyPatch) -> None:
    calibrated = warmed_warmgear(5.0)
    seen: list[tuple[Any, bool]] = []

    def unit_profile(unit: int, *_: object) -> tuple[Any, Any]:
        return load_profile(EXAMPLE), calibrated

    def run(s: object, method: str, seed: int, profile: object, make: Any,
            condition: bool) -> object:
        seen.append((make(), condition))
        rmse = {"none": 10.0, "paper": 4.0, "ours": 1.0}[method]
        return argparse.Namespace(rmse_deg=rmse, ptpe_deg=2 * rmse)

    monkeypatch.setattr(family_accuracy, "unit_profile", unit_profile)
    monkeypatch.setattr(family_accuracy, "run_scenario", run)
    monkeypatch.setattr(family_accuracy, "compute_time_us", lambda *a, **k: (1.0, 2.0))
    args = family_accuracy.namespace_from(argparse.Namespace(
        unit_seeds="1", quick=True, no_extra=True))
    assert family_accuracy.main(args) == 0
    assert seen and all(isinstance(p, CarriedPlant) and cond for p, cond in seen)
    assert all(p.t_s == pytest.approx(5.0) for p, _ in seen)
    assert len({id(p.plant) for p, _ in seen}) == len(seen)


def test_the_family_bench_compares_the_paper_and_ours_alone_when_asked(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    def run(s: object, method: str, *_: object) -> object:
        rmse = {"paper": 4.0, "ours": 1.0}[method]
        return argparse.Namespace(rmse_deg=rmse, ptpe_deg=2 * rmse)

    monkeypatch.setattr(family_accuracy, "unit_profile",
                        lambda *_: (load_profile(EXAMPLE), warmed_warmgear(1.0)))
    monkeypatch.setattr(family_accuracy, "run_scenario", run)
    monkeypatch.setattr(family_accuracy, "compute_time_us", lambda *a, **k: (1.0, 2.0))
    args = family_accuracy.namespace_from(argparse.Namespace(
        unit_seeds="1", quick=True, no_extra=True, methods="paper,ours"))
    assert family_accuracy.main(args) == 0
    assert "| 4.00/8.0 | 1.00/2.0 | nan | nan | 0.25 |" in capsys.readouterr().out
