"""Ours' plateau heights read off the sheet unit's tracked flats (session 28): where the one
omega drawn back from the reference point misses the flat the tip stands on."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from support.profiles import ROOT, assert_sheet_knob_field_round_trips, make_profile
from support.tension_sweeps import SHEET_KNOB, sweep

from tsmd.calibration.tension_play_fit import fit_tension_play
from tsmd.cli import main
from tsmd.compensation.model_parts import model_parts
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.datasheet_flat_heights import (
    FlatRow,
    flats_at_zero,
    flats_kept,
    own_rows,
    tracked_flats,
    with_heights,
)
from tsmd.datasheet_level_grid import TrackedSweep
from tsmd.profile import DeviceKnob

GRID = (-90.0, 0.0, 90.0)
LUMPED = ROOT / "profiles" / "devices" / "family" / "lumped.yaml"



def fitted(knob: DeviceKnob) -> TensionPlayParams:
    return fit_tension_play([sweep(g) for g in GRID], knob)


def tracked(params: TensionPlayParams, cycles: float = 3.0) -> TrackedSweep:
    """A sweep of the knob whose tip is ``params``' model exactly (the other knob at 0)."""
    t = np.arange(0.0, cycles / 0.04, 0.02)
    x = 90.0 * np.sin(2 * math.pi * 0.04 * t)
    other = np.zeros_like(x)
    y, _ = model_parts(x, other, params, 0.0)
    return TrackedSweep(x, other, y)


def test_flat_heights_replace_the_heights_drawn_from_the_reference_point() -> None:
    knob = dataclasses.replace(SHEET_KNOB, flat_height_pos_deg=-9.5, flat_height_neg_deg=11.0)
    p = fitted(knob)
    assert (p.height_pos_deg, p.height_neg_deg) == (-9.5, 11.0)


def test_without_flat_heights_the_fit_is_unchanged() -> None:
    p = fitted(SHEET_KNOB)
    assert p.height_pos_deg == pytest.approx(100.0 - 1.5 * (90.0 - 25.0))
    assert p.height_neg_deg == pytest.approx(-100.0 + 1.5 * (90.0 - 25.0))


def test_one_flat_alone_leaves_the_drawn_heights() -> None:
    knob = dataclasses.replace(SHEET_KNOB, flat_height_pos_deg=-9.5)
    assert fitted(knob) == fitted(SHEET_KNOB)


def test_flat_heights_leave_every_other_parameter_of_the_unit() -> None:
    knob = dataclasses.replace(SHEET_KNOB, flat_height_pos_deg=-9.5, flat_height_neg_deg=11.0)
    drawn, flat = fitted(SHEET_KNOB), fitted(knob)
    assert dataclasses.replace(flat, height_pos_deg=drawn.height_pos_deg,
                               height_neg_deg=drawn.height_neg_deg) == drawn


def test_tracked_flats_are_the_tip_where_the_knob_crosses_zero_each_way() -> None:
    truth = dataclasses.replace(fitted(SHEET_KNOB), height_pos_deg=-8.0, height_neg_deg=9.0)
    up, down = tracked_flats([tracked(truth)])
    assert up == pytest.approx(-8.0, abs=0.01)
    assert down == pytest.approx(9.0, abs=0.01)


def test_a_sweep_that_never_crosses_zero_gives_no_flat() -> None:
    x = np.linspace(30.0, 80.0, 500)
    up, down = tracked_flats([TrackedSweep(x, np.zeros_like(x), x)])
    assert math.isnan(up) and math.isnan(down)


def test_flats_read_at_the_other_knobs_zero_only() -> None:
    drawn = fitted(SHEET_KNOB)
    truth = dataclasses.replace(drawn, height_pos_deg=-8.0, height_neg_deg=9.0)
    assert flats_at_zero([(90.0, tracked(drawn)), (0.0, tracked(truth))]) == \
        pytest.approx((-8.0, 9.0), abs=0.01)
    assert flats_at_zero([(90.0, tracked(truth))]) is None


def test_crossed_flats_are_no_reading() -> None:
    x = 90.0 * np.sin(2 * math.pi * 0.04 * np.arange(0.0, 75.0, 0.02))
    tip = np.where(np.gradient(x) > 0, 9.0, -8.0)  # up stands above down: no play's flats
    assert flats_at_zero([(0.0, TrackedSweep(x, np.zeros_like(x), tip))]) is None


def test_flats_kept_where_the_rows_track_better() -> None:
    assert flats_kept([FlatRow("a", 3.0, 1.5, 0.05), FlatRow("b", 2.0, 1.9, 0.05)])


def test_no_row_may_rise_beyond_its_noise_even_below_the_worst_drawn_row() -> None:
    # the sample's unit 202 (session 28): 2.00 -> 4.05 under 201's worse drawn rows
    assert not flats_kept([FlatRow("a", 4.94, 0.91, 0.004), FlatRow("b", 2.00, 4.05, 0.004)])


def test_flats_not_kept_where_the_worst_row_gets_worse() -> None:
    # unit 0's phi2 (session 28): the squared sum falls, but one row ends above the worst
    rows = [FlatRow("a", 2.586, 2.233, 0.004), FlatRow("b", 2.651, 3.026, 0.003),
            FlatRow("c", 2.964, 1.833, 0.003)]
    assert not flats_kept(rows)


def test_a_rise_within_its_noise_does_not_decide() -> None:
    assert flats_kept([FlatRow("a", 3.0, 3.04, 0.05), FlatRow("b", 2.0, 2.03, 0.05),
                       FlatRow("c", 2.5, 1.0, 0.05)])


def test_flats_not_kept_where_the_squared_sum_does_not_fall() -> None:
    assert not flats_kept([FlatRow("a", 2.0, 2.0, 0.1), FlatRow("b", 1.0, 1.05, 0.1)])
    assert not flats_kept([])


def test_the_rows_are_the_knobs_own_with_the_other_knob_still() -> None:
    for knob in (0, 1):
        rows = own_rows(knob)
        assert rows and all(s.knobs == (knob,) for s in rows)
        assert all(np.ptp(s.q_deg[:, 1 - knob]) == 0.0 for s in rows)


def test_with_heights_moves_one_knobs_heights_only() -> None:
    profile = make_profile(d0=21.0)
    moved = with_heights(profile, 1, -3.0, 2.0)
    assert moved.knobs[0] == profile.knobs[0]
    tp, old = moved.knobs[1].tension_play, profile.knobs[1].tension_play
    assert tp is not None and old is not None
    assert (tp.height_pos_deg, tp.height_neg_deg) == pytest.approx(
        (old.height_pos_deg - 3.0, old.height_neg_deg + 2.0))
    assert dataclasses.replace(tp, height_pos_deg=old.height_pos_deg,
                               height_neg_deg=old.height_neg_deg) == old


def test_sheet_keys_round_trip_and_their_range() -> None:
    assert_sheet_knob_field_round_trips("flat_height_pos_deg", 1, -10.34, -50.0)
    assert_sheet_knob_field_round_trips("flat_height_neg_deg", 0, 12.41, 50.0)


@pytest.mark.parametrize("extra", [[], ["--update", str(LUMPED)]])
def test_a_flat_sample_without_update_and_flat_heights_is_refused(
        extra: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["datasheet", "--plant", "simrig.family:make_family_plant", "--params",
                 '{"plant":"lumped","unit":0}', "--device-model", "m", "--flat-sample", "201",
                 "--out", str(tmp_path / "d.yaml"), *extra]) == 2
    err = capsys.readouterr().err
    assert "--flat-sample goes with --update and --flat-heights" in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "d.yaml").exists()
