"""Each unit's knee from its own current: the loaded ramp's knee, the template's knee moved from
the sheet unit's to the unit's, and the profile, sheet and commands that carry it."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from test_compensation_loaded_shape import params, sweep_path
from test_compensation_shape_grid import KNEE, NEAR_STRAIGHT, commands, grid
from test_compensation_tension_play_fit import DEVICE_KNOB, synthetic_sweep

from tsmd.calibration.loaded_knee import read_loaded_knee
from tsmd.calibration.tension_play_fit import fit_tension_play
from tsmd.compensation.knee_map import KNEE_RATIO_RANGE, moved_knee
from tsmd.compensation.loaded_shape import LoadedShape
from tsmd.compensation.tension_play_params import tension_play_from_mapping, tension_play_to_mapping
from tsmd.profile import load_device_model, save_device_model
from tsmd.profile.device import DeviceModel
from tsmd.profile.reading_offset import OffsetGrid, ReadingOffset

STRAIGHT_KNOTS = LoadedShape((0.0, 10.0, 60.0), (0.0, 10.0, 60.0))
SHEET_KNEE = (30.0, 30.0)


def kneed_sweep(knee_deg: float, edge_deg: float = 20.0, seed: int = 0
                ) -> tuple[np.ndarray, np.ndarray]:
    """A +-90 deg sweep whose loaded current rises 3.5 mA/deg past the edge, then 0.7 past
    ``knee_deg`` of travel (both sides, mirrored), with friction and noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 75.0, 0.004)
    pos = -90.0 * np.cos(2 * math.pi * 0.04 * t)
    v = np.gradient(pos)
    u = np.abs(pos) - edge_deg
    ramp = np.where(u > 0, 0.0035 * np.minimum(u, knee_deg) + 0.0007 * np.maximum(u - knee_deg, 0),
                    0.0)
    outward = np.sign(pos) * v > 0
    current = 0.03 * np.sign(v) + np.where(outward, np.sign(pos) * ramp, 0.0)
    return pos, current + rng.normal(0.0, 0.001, t.size)


def test_the_loaded_ramps_knee_is_read_from_the_current() -> None:
    pos, cur = kneed_sweep(27.0)
    for side in (1, -1):
        knee = read_loaded_knee(pos, cur, 20.0 * side, side)
        assert knee is not None and knee.travel_deg == pytest.approx(27.0, abs=0.5)
        assert knee.passes >= 2 and knee.u95_deg < 1.0


def test_a_ramp_without_a_knee_has_none() -> None:
    pos, cur = kneed_sweep(200.0)
    assert read_loaded_knee(pos, cur, 20.0, 1) is None


def test_a_straight_template_stays_straight_wherever_the_knee_moves() -> None:
    moved = moved_knee(STRAIGHT_KNOTS, 30.0, 26.0)
    assert moved.is_straight


def test_the_templates_knee_moves_to_the_units_keeping_each_pieces_slope() -> None:
    moved = moved_knee(KNEE, 30.0, 27.0)  # KNEE: slope 16/30 to 30, then 36/34
    assert moved.at(27.0) == pytest.approx(16.0 / 30.0 * 27.0)
    assert moved.at(37.0) - moved.at(27.0) == pytest.approx(36.0 / 34.0 * 10.0)


def test_the_knee_ratio_is_bounded() -> None:
    far = moved_knee(KNEE, 30.0, 5.0)
    assert far.at(30.0 * KNEE_RATIO_RANGE[0]) == pytest.approx(KNEE.at(30.0) * KNEE_RATIO_RANGE[0])


def test_the_profile_section_keeps_the_knees_and_old_sections_have_none() -> None:
    p = dataclasses.replace(params(shape_pos=KNEE, shape_neg=KNEE), loaded_knee_deg=(27.0, 28.5),
                            loaded_knee_u95_deg=(0.3, 0.4), sheet_loaded_knee_deg=SHEET_KNEE)
    assert tension_play_from_mapping(tension_play_to_mapping(p)) == p
    old = tension_play_from_mapping(tension_play_to_mapping(params()))
    assert old.loaded_knee_deg is None and old.sheet_loaded_knee_deg is None


def test_the_sheet_keeps_its_knee(tmp_path: pytest.TempPathFactory) -> None:
    sheet = DeviceModel("knee", (dataclasses.replace(
        DEVICE_KNOB, loaded_knee_pos_deg=29.3, loaded_knee_neg_deg=30.2), DEVICE_KNOB))
    path = tmp_path / "sheet.yaml"  # type: ignore[operator]
    save_device_model(sheet, path)
    knobs = load_device_model(path).knobs
    assert (knobs[0].loaded_knee_pos_deg, knobs[0].loaded_knee_neg_deg) == (29.3, 30.2)
    assert knobs[1].loaded_knee_pos_deg is None


@pytest.mark.parametrize("missing", ["loaded_knee_deg", "sheet_loaded_knee_deg"])
def test_without_both_knees_the_commands_are_exactly_the_templates_own(missing: str) -> None:
    path = sweep_path()
    p = dataclasses.replace(params(shape_pos=KNEE, shape_neg=KNEE),
                            shape_grid=(grid(NEAR_STRAIGHT, KNEE, NEAR_STRAIGHT),) * 2)
    knees = {"loaded_knee_deg": (25.0, 26.0), "sheet_loaded_knee_deg": SHEET_KNEE, missing: None}
    with_one = dataclasses.replace(p, **knees)
    np.testing.assert_array_equal(commands(p, path), commands(with_one, path))


def test_with_both_knees_the_commands_follow_the_units_knee() -> None:
    path = sweep_path()
    p = params(shape_pos=KNEE, shape_neg=KNEE)
    moved = dataclasses.replace(p, loaded_knee_deg=(26.0, 26.0), sheet_loaded_knee_deg=SHEET_KNEE)
    assert np.max(np.abs(commands(moved, path) - commands(p, path))) > 0.5


def test_the_fit_stores_the_units_knee_and_copies_the_sheets() -> None:
    knob = dataclasses.replace(DEVICE_KNOB, loaded_knee_pos_deg=30.0, loaded_knee_neg_deg=31.0)
    p = fit_tension_play([synthetic_sweep(a) for a in (-90.0, 0.0, 90.0)], knob)
    assert p.sheet_loaded_knee_deg == (30.0, 31.0)
    assert p.loaded_knee_deg is None  # a straight ramp shows no knee


def test_the_fit_reads_the_units_knee_past_the_edge_as_the_current_read_it() -> None:
    """Calibration subtracts the product's reading offset from the edges; the knee is read past
    the edge before that, as on the sheet's unit (else every knee moves by the offset)."""
    pos, cur = kneed_sweep(28.0, edge_deg=20.0)
    grid_deg = (-90.0, 0.0, 90.0)
    offsets = (("dead_zone_pos_deg", OffsetGrid((-1.5,) * 3, (0.1,) * 3, (4, 4, 4))),
               ("dead_zone_neg_deg", OffsetGrid((1.5,) * 3, (0.1,) * 3, (4, 4, 4))))
    # the edges as calibration hands them over: the read edges less the offset
    sweeps = [dataclasses.replace(synthetic_sweep(a), t_s=np.arange(pos.size) * 0.004,
                                  cmd_deg=pos, pos_deg=pos, current_A=cur,
                                  dead_zone_pos_deg=21.5, dead_zone_neg_deg=-21.5)
              for a in grid_deg]
    knob = dataclasses.replace(DEVICE_KNOB, reading_offset=ReadingOffset(grid_deg, offsets))
    p = fit_tension_play(sweeps, knob)
    assert p.loaded_knee_deg is not None
    assert p.loaded_knee_deg == pytest.approx((28.0, 28.0), abs=0.5)
