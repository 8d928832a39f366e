"""How far the sheet unit's tip lines move between its fresh and its calibrated state, and the
calibrated edges written less that move (session 28)."""

from __future__ import annotations

import copy
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from support.profiles import ROOT, make_profile

from simrig.plant import PlantStep
from tsmd.cli import main
from tsmd.compensation.safety import KnobLimits
from tsmd.datasheet_state_move import (
    KeptPlant,
    line_crossing_deg,
    line_moves_deg,
    state_moves_deg,
)
from tsmd.datasheet_unit_edges import with_edges_of
from tsmd.profile import DeviceKnob, DeviceModel, ReferencePoint, load_device_model

OMEGA = 1.3
SHEET_KNOB = DeviceKnob(1.5, ReferencePoint(90.0, 100.0), ReferencePoint(-90.0, -100.0),
                        KnobLimits(-90.0, 90.0, 120.0, 2000.0),
                        reference_dead_zone_pos_deg=25.0, reference_dead_zone_neg_deg=-25.0)


def dead_zone_tip(x: np.ndarray, edge_pos: float, edge_neg: float) -> np.ndarray:
    """A tip that stays at 0 between the edges and follows lines of slope OMEGA past them."""
    return OMEGA * (np.maximum(x - edge_pos, 0.0) + np.minimum(x - edge_neg, 0.0))


def swept(edge_pos: float = 20.0, edge_neg: float = -22.0, noise: float = 0.0
          ) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0.0, 25.0, 0.004)
    x = 90.0 * np.sin(2 * math.pi * 0.04 * t)
    tip = dead_zone_tip(x, edge_pos, edge_neg)
    return x, tip + noise * np.random.default_rng(0).standard_normal(tip.size)


def test_the_loaded_line_is_crossed_at_half_the_branchs_reach() -> None:
    x, tip = swept()
    at, level = line_crossing_deg(x, tip, 1)
    assert level == pytest.approx(0.5 * OMEGA * (90.0 - 20.0), abs=0.1)
    assert at == pytest.approx(20.0 + level / OMEGA, abs=0.05)


def test_a_line_moved_outward_reads_plus_on_the_positive_side_and_minus_on_the_negative() -> None:
    moves = line_moves_deg(swept(20.0, -22.0), swept(22.0, -24.5))
    assert moves == pytest.approx((2.0, -2.5), abs=0.05)


def test_a_line_moved_inward_reads_the_other_way() -> None:
    moves = line_moves_deg(swept(20.0, -22.0), swept(18.5, -21.0))
    assert moves == pytest.approx((-1.5, 1.0), abs=0.05)


def test_tracker_noise_does_not_move_an_unchanged_line() -> None:
    moves = line_moves_deg(swept(noise=0.3), swept(noise=0.3)[::-1][::-1])
    assert moves == pytest.approx((0.0, 0.0), abs=0.05)
    noisy = line_moves_deg(swept(), swept(noise=0.3))
    assert noisy == pytest.approx((0.0, 0.0), abs=0.1)


def test_a_sweep_without_a_loaded_branch_is_refused() -> None:
    x = np.zeros(100)
    with pytest.raises(ValueError, match="loaded branch"):
        line_crossing_deg(x, x, 1)


def test_the_written_edges_are_the_calibrations_less_the_mean_move() -> None:
    runs = [make_profile(d0=20.0), make_profile(d0=21.0)]
    moves = [((2.0, -2.0), (-1.0, 1.5)), ((3.0, -2.0), (-1.0, 0.5))]
    sheet = with_edges_of(DeviceModel("m", (SHEET_KNOB, SHEET_KNOB)), runs, moves)
    assert (sheet.knobs[0].calibrated_dead_zone_pos_deg,
            sheet.knobs[0].calibrated_dead_zone_neg_deg) == pytest.approx((18.0, -18.5))
    assert (sheet.knobs[1].calibrated_dead_zone_pos_deg,
            sheet.knobs[1].calibrated_dead_zone_neg_deg) == pytest.approx((21.5, -21.5))


def test_without_moves_the_written_edges_are_the_calibrations() -> None:
    runs = [make_profile(d0=20.0)]
    sheet = with_edges_of(DeviceModel("m", (SHEET_KNOB, SHEET_KNOB)), runs)
    assert sheet.knobs[0].calibrated_dead_zone_pos_deg == pytest.approx(20.0)


def test_one_move_per_calibration_is_required() -> None:
    with pytest.raises(ValueError, match="state moves"):
        with_edges_of(DeviceModel("m", (SHEET_KNOB, SHEET_KNOB)),
                      [make_profile(d0=20.0)], [((0.0, 0.0), (0.0, 0.0))] * 2)


class SettingPlant:
    """A catheter whose slack grows by ``set_deg`` on both sides once it has run ``after_s``
    (a rope's set under a calibration's loads); its reset takes the set back."""

    def __init__(self, set_deg: float = 2.0, after_s: float = 100.0) -> None:
        self.set_deg, self.after_s = set_deg, after_s
        self.reset()

    def reset(self) -> None:
        self.elapsed_s = 0.0

    def step(self, dt_s: float, knob_deg: np.ndarray) -> PlantStep:
        self.elapsed_s += dt_s
        slack = 20.0 + (self.set_deg if self.elapsed_s > self.after_s else 0.0)
        tip = dead_zone_tip(np.asarray(knob_deg, float), slack, -slack)
        return PlantStep(tip_deg=tip, knob_torque_Nm=0.002 * tip)


def test_kept_plant_is_not_reset_by_the_rig() -> None:
    plant = SettingPlant()
    plant.elapsed_s = 500.0
    KeptPlant(plant).reset()
    assert plant.elapsed_s == 500.0


def test_the_state_move_is_the_tips_set_over_the_calibration_and_the_plant_is_left_as_it_was(
        ) -> None:
    calibrated = SettingPlant(set_deg=2.0, after_s=1000.0)
    calibrated.elapsed_s = 2000.0  # the set taken during a calibration
    before = copy.deepcopy(calibrated.__dict__)
    moves = state_moves_deg(lambda: SettingPlant(set_deg=2.0, after_s=1000.0), calibrated, 0,
                            cycles=1.0)
    for pos, neg in moves:
        assert pos == pytest.approx(2.0, abs=0.3)
        assert neg == pytest.approx(-2.0, abs=0.3)
    assert calibrated.__dict__ == before


LUMPED = ROOT / "profiles" / "devices" / "family" / "lumped.yaml"
PLANT = ["--plant", "simrig.family:make_family_plant", "--params", '{"plant":"lumped","unit":0}']


@pytest.mark.parametrize("flags, less_move", [([], False), (["--unit-edges-move"], True)])
def test_the_update_subtracts_the_move_only_with_its_flag_and_says_so(
        flags: list[str], less_move: bool, tmp_path: Path,
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Session 26's stage stays reproducible: the move is subtracted only when asked for."""
    asked: list[bool] = []

    def fake(device: DeviceModel, config: object, factory: object, seeds: object,
             less: bool = False) -> DeviceModel:
        asked.append(less)
        knobs = tuple(dataclasses.replace(k, calibrated_dead_zone_pos_deg=21.0,
                                          calibrated_dead_zone_neg_deg=-21.0)
                      for k in device.knobs)
        return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))

    monkeypatch.setattr("tsmd.commands.datasheet_update.with_unit_edges", fake)
    out = tmp_path / "new.yaml"
    assert main(["datasheet", "--update", str(LUMPED), *PLANT, "--unit-edges", *flags,
                 "--out", str(out)]) == 0
    assert asked == [less_move]
    assert load_device_model(out).knobs[0].calibrated_dead_zone_pos_deg == 21.0
    header = out.read_text().split("schema_version")[0]
    assert ("--unit-edges-move" in header) == less_move
    assert ("tip swept fresh and calibrated" in header) == less_move
