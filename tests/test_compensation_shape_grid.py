"""The loaded-branch templates over the other knob's angle (ShapeGrid): interpolation, the sheet
and profile sections, the fit and the compensator's table."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from test_compensation_loaded_shape import LIMITS, PERIOD_S, SOFT_START, params, sweep_path
from test_compensation_tension_play_fit import DEVICE_KNOB, synthetic_sweep

from tsmd.calibration.tension_play_fit import fit_tension_play
from tsmd.compensation.loaded_shape import LoadedShape, ShapeGrid, shape_grid_from_mapping
from tsmd.compensation.ours import OursCompensator
from tsmd.compensation.ours_table import ours_knobs
from tsmd.compensation.tension_play_params import (
    TensionPlayParams,
    tension_play_from_mapping,
    tension_play_to_mapping,
)
from tsmd.profile import load_device_model, save_device_model
from tsmd.profile.device import DeviceModel
from tsmd.profile.types import ProfileError

KNEE = LoadedShape((0.0, 30.0, 64.0), (0.0, 16.0, 52.0))
NEAR_STRAIGHT = LoadedShape((0.0, 20.0, 67.0), (0.0, 18.0, 60.0))


def grid(*shapes: LoadedShape) -> ShapeGrid:
    angles = np.linspace(-90.0, 90.0, len(shapes))
    return ShapeGrid(tuple(float(a) for a in angles), shapes)


def commands(p: TensionPlayParams, path: np.ndarray) -> np.ndarray:
    comp = OursCompensator(ours_knobs((p, p)), PERIOD_S, (LIMITS, LIMITS))
    comp.reset(path[0])
    return np.array([comp.command(q, PERIOD_S) for q in path])


def test_the_template_at_a_grid_angle_is_that_angles() -> None:
    g = grid(NEAR_STRAIGHT, KNEE, NEAR_STRAIGHT)
    assert g.at(0.0) == KNEE
    assert g.at(90.0) == NEAR_STRAIGHT


def test_between_two_angles_the_template_is_their_weighted_mean_at_every_knot() -> None:
    g = grid(NEAR_STRAIGHT, KNEE, NEAR_STRAIGHT)
    mid = g.at(45.0)
    for u in (*KNEE.travel_deg, *NEAR_STRAIGHT.travel_deg, 50.0):
        assert mid.at(u) == pytest.approx(0.5 * (KNEE.at(u) + NEAR_STRAIGHT.at(u)))


def test_beyond_the_grid_the_end_template_is_held() -> None:
    g = ShapeGrid((-60.0, 60.0), (KNEE, NEAR_STRAIGHT))
    assert g.at(-90.0) == KNEE and g.at(90.0) == NEAR_STRAIGHT and g.at(float("nan")) == KNEE


@pytest.mark.parametrize(("raw", "message"), [
    ({"other_knob_deg": [0.0, -90.0], "pos": [{"travel_deg": [0, 1], "shaped_deg": [0, 1]}] * 2,
      "neg": [{"travel_deg": [0, 1], "shaped_deg": [0, 1]}] * 2}, "increase strictly"),
    ({"other_knob_deg": [-90.0, 90.0], "pos": [{"travel_deg": [0, 1], "shaped_deg": [0, 1]}],
      "neg": [{"travel_deg": [0, 1], "shaped_deg": [0, 1]}] * 2}, "one template each"),
    ({"other_knob_deg": [-90.0, 90.0], "pos": [], "neg": [], "side": 1}, "unknown key"),
])
def test_a_bad_grid_is_refused_in_one_line_naming_the_key(raw: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message) as err:
        shape_grid_from_mapping(raw, "loaded_shape_grid")
    assert "loaded_shape_grid" in str(err.value) and "\n" not in str(err.value)


def test_the_profile_section_keeps_the_grid_and_old_sections_have_none() -> None:
    p = dataclasses.replace(params(shape_pos=KNEE, shape_neg=KNEE),
                            shape_grid=(grid(NEAR_STRAIGHT, KNEE), grid(KNEE, NEAR_STRAIGHT)))
    assert tension_play_from_mapping(tension_play_to_mapping(p)) == p
    assert tension_play_from_mapping(tension_play_to_mapping(params())).shape_grid is None


def test_the_sheet_keeps_the_grid(tmp_path: pytest.TempPathFactory) -> None:
    sheet = DeviceModel("grid", (dataclasses.replace(
        DEVICE_KNOB, loaded_shape_grid=(grid(NEAR_STRAIGHT, KNEE), grid(KNEE, KNEE))),
        DEVICE_KNOB))
    path = tmp_path / "sheet.yaml"  # type: ignore[operator]
    save_device_model(sheet, path)
    assert load_device_model(path).knobs[0].loaded_shape_grid == sheet.knobs[0].loaded_shape_grid
    assert load_device_model(path).knobs[1].loaded_shape_grid is None


def test_a_sheet_with_a_bad_grid_is_refused_in_one_line(tmp_path: pytest.TempPathFactory
                                                        ) -> None:
    path = tmp_path / "sheet.yaml"  # type: ignore[operator]
    save_device_model(DeviceModel("grid", (DEVICE_KNOB, DEVICE_KNOB)), path)
    text = path.read_text().replace("  phi2:\n", "    loaded_shape_grid: {other_knob_deg: [0]}\n"
                                    "  phi2:\n", 1)
    path.write_text(text)
    with pytest.raises(ProfileError, match="loaded_shape_grid") as err:
        load_device_model(path)
    assert "\n" not in str(err.value)


def test_a_grid_of_one_template_commands_exactly_as_that_template_alone() -> None:
    path = sweep_path()
    one = params(shape_pos=SOFT_START, shape_neg=KNEE)
    same = dataclasses.replace(one, shape_grid=(grid(SOFT_START, SOFT_START),
                                                grid(KNEE, KNEE)))
    np.testing.assert_array_equal(commands(one, path), commands(same, path))


def test_the_other_knobs_angle_picks_the_template() -> None:
    path = sweep_path()  # the other knob moves +-50 deg
    p = params(shape_pos=KNEE, shape_neg=KNEE)
    varying = dataclasses.replace(p, shape_grid=(grid(NEAR_STRAIGHT, KNEE, NEAR_STRAIGHT),) * 2)
    assert np.max(np.abs(commands(varying, path) - commands(p, path))) > 1.0


def test_the_fit_copies_the_grid_and_draws_h_through_the_template_at_the_other_knobs_0(
) -> None:
    g = (grid(NEAR_STRAIGHT, KNEE, NEAR_STRAIGHT), grid(NEAR_STRAIGHT, KNEE, NEAR_STRAIGHT))
    knob = dataclasses.replace(DEVICE_KNOB, reference_dead_zone_pos_deg=25.0,
                               reference_dead_zone_neg_deg=-25.0, loaded_shape_grid=g)
    p = fit_tension_play([synthetic_sweep(a) for a in (-90.0, 90.0)], knob)
    assert p.shape_grid == g
    assert p.shape_pos == KNEE and p.shape_neg == KNEE
    # the reference point (+-90 deg knob, +-100 deg tip) on the bent line from the edge at 25
    assert p.height_pos_deg == pytest.approx(100.0 - DEVICE_KNOB.omega * KNEE.at(65.0))
