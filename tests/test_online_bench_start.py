"""Where a `tsmd bench online` run starts: the plant its calibration left, or a fresh one."""

from __future__ import annotations

import argparse
import pickle
import shutil
from pathlib import Path

import numpy as np
import pytest

from simrig.scenario import ShapeChange, ShapeChangePlant
from tsmd.bench import online_start
from tsmd.bench.online import add_arguments
from tsmd.bench.online_start import calibrated_with_plant, run_plant
from tsmd.bench.online_units import make_unit, shape_change
from tsmd.carried_plant import CarriedPlant

EXAMPLE = Path(__file__).resolve().parents[1] / "profiles" / "example-sim.yaml"


def soaked_notchclutch(seconds: float) -> object:
    """Notchclutch unit 1 stepped ``seconds`` of plant time at rest (its liner soaks)."""
    sim = make_unit("notchclutch", 1, [])
    sim.reset()
    for _ in range(int(seconds / 0.004)):
        sim.step(0.004, np.zeros(2))
    return sim.plant


def test_the_bench_starts_from_the_calibrated_plant_unless_asked() -> None:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    assert parser.parse_args([]).start == "calibrated"
    assert parser.parse_args(["--start", "fresh"]).start == "fresh"


def test_a_carried_plant_keeps_its_state_through_the_rigs_reset() -> None:
    plant = soaked_notchclutch(2.0)
    carried = CarriedPlant(plant)
    carried.reset()
    assert plant.t_s == pytest.approx(2.0, abs=0.01)


def test_a_calibrated_start_runs_a_copy_that_goes_on_from_the_calibrated_state() -> None:
    plant = soaked_notchclutch(2.0)
    sim = run_plant("calibrated", "notchclutch", 1, plant, [])
    sim.reset()
    sim.step(0.004, np.zeros(2))
    assert sim.plant.t_s == pytest.approx(2.004, abs=0.01)
    assert plant.t_s == pytest.approx(2.0, abs=0.01)  # the calibrated plant is not driven


def test_a_fresh_start_builds_the_unit_anew() -> None:
    sim = run_plant("fresh", "notchclutch", 1, soaked_notchclutch(2.0), [])
    sim.reset()
    sim.step(0.004, np.zeros(2))
    assert sim.plant.t_s == pytest.approx(0.004)


def test_a_shape_change_applies_to_the_calibrated_plant_at_the_runs_time() -> None:
    plant = soaked_notchclutch(2.0)
    sim = run_plant("calibrated", "notchclutch", 1, plant,
                    [ShapeChange(0.008, shape_change("slack:0.5"))])
    sim.reset()
    sim.step(0.004, np.zeros(2))
    assert sim.plant.slack_delta_mm == ((0.0, 0.0), (0.0, 0.0))
    sim.step(0.004, np.zeros(2))
    assert sim.plant.slack_delta_mm == ((0.5, 0.5), (0.5, 0.5))


def test_a_cached_profile_and_plant_are_taken_without_calibrating(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def no_calibration(*_: object, **__: object) -> None:
        raise AssertionError("calibrated again")

    monkeypatch.setattr(online_start, "calibrate_unit", no_calibration)
    shutil.copy(EXAMPLE, tmp_path / "notchclutch-unit1-straight.yaml")
    with (tmp_path / "notchclutch-unit1-straight.plant.pkl").open("wb") as f:
        pickle.dump(soaked_notchclutch(2.0), f)
    profile, plant = calibrated_with_plant("notchclutch", 1, None, None, tmp_path, "straight")
    assert plant.t_s == pytest.approx(2.0, abs=0.01) and profile is not None


def test_a_cached_profile_without_its_plant_is_calibrated_again(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[str] = []

    def counted(plant: str, unit: int, change: object, device: object, label: str
                ) -> tuple[None, ShapeChangePlant]:
        calls.append(f"{plant}-unit{unit}-{label}")
        return None, make_unit(plant, unit, [])

    monkeypatch.setattr(online_start, "calibrate_unit", counted)
    shutil.copy(EXAMPLE, tmp_path / "notchclutch-unit1-straight.yaml")
    calibrated_with_plant("notchclutch", 1, None, None, tmp_path, "straight")
    assert calls == ["notchclutch-unit1-straight"]
    assert (tmp_path / "notchclutch-unit1-straight.plant.pkl").exists()
