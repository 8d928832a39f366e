"""The dead-zone edge fit over a handle's torque ripple (a detent, cogging): the ripple taken out
of the current (tsmd.calibration.pieces.ripple_removed, folded on its period around the
one-period mean, tsmd.calibration.pieces.period_mean) before the edge is fitted."""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.pieces import fitted_edge, period_mean, ripple_removed
from tsmd.commands import datasheet as datasheet_command
from tsmd.commands.datasheet_args import add_arguments
from tsmd.datasheet import DatasheetError
from tsmd.errors import TsmdError
from tsmd.profile.files import load_device_model
from tsmd.profile.sheet_schema import device_model_from_mapping, device_model_to_mapping

NOISE_A = 0.0005
PERIOD_DEG = 15.0
EDGE_DEG = 20.0
SNAKEDENT_SHEET = Path(__file__).parents[1] / "profiles/devices/family/snakedent.yaml"


def _rippled_hinge(x: np.ndarray, phase_deg: float) -> np.ndarray:
    """A dead-zone level, a loaded ramp of 2.2 mA/deg from ``EDGE_DEG`` and a 4 mA ripple of
    ``PERIOD_DEG`` (its slope 1.7 mA/deg: a notch's steep-then-shallow stretch on the ramp)."""
    ramp = 0.02 + 0.0022 * np.maximum(x - EDGE_DEG, 0.0)
    ripple = 0.004 * np.sin(2.0 * np.pi * (x - phase_deg) / PERIOD_DEG)
    return ramp + ripple + np.random.default_rng(1).normal(0.0, NOISE_A, x.size)


STRETCH_START_DEG = 16.0


def _stretch_then_ramp(x: np.ndarray) -> np.ndarray:
    """The rope stretching while the tip is held (6 mA/deg from ``STRETCH_START_DEG``), then the
    loaded ramp (2.2 mA/deg) from ``EDGE_DEG``, where the tip lets go."""
    return (0.02 + 0.006 * np.clip(x - STRETCH_START_DEG, 0.0, EDGE_DEG - STRETCH_START_DEG)
            + 0.0022 * np.maximum(x - EDGE_DEG, 0.0))


def _ripple(x: np.ndarray, phase_deg: float) -> np.ndarray:
    return 0.004 * np.sin(2.0 * np.pi * (x - phase_deg) / PERIOD_DEG)


@pytest.mark.parametrize("phase_deg", [0.0, 5.0, 10.0])
def test_the_ripple_taken_out_leaves_the_current_it_rode_on(phase_deg: float) -> None:
    x = np.arange(-90.0, 90.0, 0.25)
    clean = _stretch_then_ramp(x)
    cleaned = ripple_removed(x, clean + _ripple(x, phase_deg), PERIOD_DEG)
    assert np.max(np.abs((cleaned - clean) - np.mean(cleaned - clean))) < 4e-4  # of 4 mA


@pytest.mark.parametrize("phase_deg", [0.0, 2.5, 5.0, 7.5, 10.0, 12.5])
def test_a_rope_stretch_under_the_ripple_reads_at_its_end_whatever_the_notch_phase(
        phase_deg: float) -> None:
    x = np.arange(-90.0, 90.0, 0.25)
    y = (_stretch_then_ramp(x) + _ripple(x, phase_deg)
         + np.random.default_rng(2).normal(0.0, NOISE_A, x.size))
    k = int(np.searchsorted(x, STRETCH_START_DEG))
    opts = replace(IdentifyOptions(edge="fit", edge_curve=True),
                   torque_ripple_period_deg=PERIOD_DEG)
    assert abs(x[fitted_edge(x, y, 0, k, NOISE_A, opts)] - EDGE_DEG) < 1.0


def test_one_period_mean_removes_the_ripple_and_keeps_a_line() -> None:
    x = np.arange(-60.0, 80.0, 0.25)
    line = 0.01 + 0.002 * x
    y = line + 0.004 * np.sin(2.0 * np.pi * x / PERIOD_DEG)
    xs, ys = period_mean(x, y, 0, x.size, PERIOD_DEG)
    assert np.max(np.abs(ys - (0.01 + 0.002 * xs))) < 2e-4


@pytest.mark.parametrize("phase_deg", [0.0, 5.0, 7.5, 12.5])
def test_the_edge_fitted_over_the_ripple_period_stays_at_the_ramp_whatever_the_notch_phase(
        phase_deg: float) -> None:
    x = np.arange(-60.0, 80.0, 0.25)
    y = _rippled_hinge(x, phase_deg)
    k = int(np.searchsorted(x, EDGE_DEG))
    opts = replace(IdentifyOptions(edge="fit", edge_curve=True),
                   torque_ripple_period_deg=PERIOD_DEG)
    assert abs(x[fitted_edge(x, y, 0, k, NOISE_A, opts)] - EDGE_DEG) < 1.5


def test_without_the_period_a_notch_on_the_ramp_reads_as_a_late_knee() -> None:
    x = np.arange(-60.0, 80.0, 0.25)
    y = _rippled_hinge(x, 12.5)
    k = int(np.searchsorted(x, EDGE_DEG))
    opts = IdentifyOptions(edge="fit", edge_curve=True)
    assert x[fitted_edge(x, y, 0, k, NOISE_A, opts)] - EDGE_DEG > 5.0


def test_the_sheet_carries_the_ripple_period_per_knob() -> None:
    device = load_device_model(SNAKEDENT_SHEET)
    knobs = tuple(replace(k, torque_ripple_period_deg=PERIOD_DEG) for k in device.knobs)
    with_period = replace(device, knobs=knobs)
    read = device_model_from_mapping(device_model_to_mapping(with_period))
    assert [k.torque_ripple_period_deg for k in read.knobs] == [PERIOD_DEG, PERIOD_DEG]


def test_a_ripple_period_out_of_range_is_refused() -> None:
    device = load_device_model(SNAKEDENT_SHEET)
    data = device_model_to_mapping(device)
    data["knobs"]["phi1"]["torque_ripple_period_deg"] = 0.1
    with pytest.raises(TsmdError, match="torque_ripple_period_deg"):
        device_model_from_mapping(data)


def test_datasheet_takes_the_ripple_period_as_a_design_constant() -> None:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    args = parser.parse_args(["--plant", "m:f", "--out", "x.yaml",
                              "--torque-ripple-period-deg", "15"])
    assert args.torque_ripple_period_deg == 15.0


@pytest.mark.parametrize("period_deg", [0.5, 120.0])
def test_datasheet_refuses_a_ripple_period_outside_its_range_by_name(period_deg: float) -> None:
    with pytest.raises(DatasheetError, match="--torque-ripple-period-deg"):
        parser = argparse.ArgumentParser()
        add_arguments(parser)
        datasheet_command.main(parser.parse_args([
            "--plant", "simrig.family:make_family_plant", "--device-model", "x", "--out",
            "x.yaml", "--torque-ripple-period-deg", str(period_deg)]))
