"""Whether a product's loaded-branch templates go into its sheet, chosen on the sheet's unit
(tsmd.datasheet_shape_choice)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from support.tracked import tracked_sweeps

from tsmd.cli import main
from tsmd.compensation.loaded_shape import LoadedShape, shaped_height
from tsmd.compensation.paper import plateau_heights
from tsmd.compensation.safety import KnobLimits
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.datasheet_level_grid import TrackedSweep
from tsmd.datasheet_shape_choice import (
    MIN_SHAPE_GAIN_DEG,
    branch_rms,
    choose_shape,
    straight,
    without_shapes,
)
from tsmd.profile.device import DeviceKnob, ReferencePoint

ANGLES = (-60.0, 0.0, 60.0)
EDGE_DEG = 24.0
SOFT_START = LoadedShape((0.0, 2.5, 5.0, 10.0, 15.0, 66.0), (0.0, 1.3, 2.2, 4.5, 8.1, 57.5))
"""A soft engagement like jawcrimp's unit 0 (T(u)/u 0.5 at 5 deg, straight from 15)."""
MILD = LoadedShape((0.0, 5.0, 66.0), (0.0, 4.7, 65.7))
"""Nearly straight: the line through the reference point misses it by 0.3 deg at most."""
KNOB = DeviceKnob(1.37, ReferencePoint(90.0, 78.4), ReferencePoint(-90.0, -78.4),
                  KnobLimits(-90.0, 90.0, 120.0, 2000.0),
                  reference_dead_zone_pos_deg=EDGE_DEG, reference_dead_zone_neg_deg=-EDGE_DEG)


def bent(shape: LoadedShape = SOFT_START) -> TensionPlayParams:
    """A unit calibrated under the sheet with the templates (edges at the sheet's)."""
    h_pos = shaped_height(90.0, 78.4, EDGE_DEG, 1.37, shape)
    h_neg = shaped_height(-90.0, -78.4, -EDGE_DEG, 1.37, shape)
    return TensionPlayParams(1.37, h_pos, h_neg, ANGLES, (EDGE_DEG,) * 3, (-EDGE_DEG,) * 3,
                             (0.1,) * 3, (0.1,) * 3, (-60.0,) * 3, (60.0,) * 3,
                             shape_pos=shape, shape_neg=shape)


def sweeps_of(truth: TensionPlayParams) -> list[TrackedSweep]:
    """One sweep per angle, the other knob held there."""
    return [sweep for _, sweep in tracked_sweeps(truth, ANGLES)]


def test_the_straight_counterpart_draws_its_lines_through_the_reference_points() -> None:
    plain = straight(bent(), KNOB)
    assert plain.shape_pos is None and plain.shape_neg is None
    assert (plain.height_pos_deg, plain.height_neg_deg) == pytest.approx(
        plateau_heights(KNOB, EDGE_DEG, -EDGE_DEG))


def test_a_softly_engaging_tip_keeps_the_templates() -> None:
    choice = choose_shape(sweeps_of(bent()), bent(), KNOB)
    assert choice.bent_rms_deg < 0.1
    assert choice.straight_rms_deg > 1.0
    assert choice.keep


def test_a_straight_tip_keeps_straight_lines() -> None:
    choice = choose_shape(sweeps_of(straight(bent(), KNOB)), bent(), KNOB)
    assert choice.straight_rms_deg < 0.1
    assert not choice.keep


def test_a_gain_below_the_threshold_keeps_straight_lines() -> None:
    mild = bent(MILD)
    choice = choose_shape(sweeps_of(mild), mild, KNOB)
    assert 0.0 < choice.straight_rms_deg - choice.bent_rms_deg < MIN_SHAPE_GAIN_DEG
    assert not choice.keep


def test_without_loaded_samples_the_rms_is_nan() -> None:
    x = np.zeros(200)
    assert np.isnan(branch_rms([TrackedSweep(x, x, x)], bent()))


def test_a_knob_left_straight_loses_its_templates_and_knees() -> None:
    knob = dataclasses.replace(KNOB, loaded_shape_pos=SOFT_START, loaded_shape_neg=SOFT_START,
                               loaded_knee_pos_deg=17.0, loaded_knee_neg_deg=16.6)
    plain = without_shapes(knob)
    assert (plain.loaded_shape_pos, plain.loaded_shape_neg, plain.loaded_knee_pos_deg,
            plain.loaded_knee_neg_deg) == (None, None, None, None)
    assert plain.omega == knob.omega


@pytest.mark.parametrize("extra", [["--loaded-shape"], []])
def test_the_choice_without_a_plant_or_with_loaded_shape_is_refused_in_one_line(
        extra: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    source = (["--plant", "simrig.plants.capstan:make_tendon_sheath_plant"] if extra
              else ["--from-recording", str(tmp_path / "a.csv"), str(tmp_path / "b.csv")])
    code = main(["datasheet", *source, *extra, "--choose-loaded-shape", "--device-model", "x",
                 "--out", str(tmp_path / "d.yaml")])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert "--choose-loaded-shape" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "d.yaml").exists()
