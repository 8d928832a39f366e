"""The dead-zone loop (session 25): each unit's plateau gap from its motor current, and the
plateau heights it moves against the data sheet's."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from support.profiles import assert_sheet_knob_field_round_trips
from test_compensation_tension_play_fit import DEVICE_KNOB, synthetic_sweep

from tsmd.calibration.dead_zone_loop import (
    LOOP_AMPLITUDE_DEG,
    LoopEdges,
    loop_move,
    loop_points,
    plateau_shift_deg,
    play_loops,
    read_loop_edges,
    wants_loop,
)
from tsmd.calibration.errors import CalibrationError
from tsmd.calibration.tension_play_fit import fit_tension_play
from tsmd.datasheet_plateau_gap import SheetLoop, tracked_flats
from tsmd.profile import DeviceModel
from tsmd.recording import Recording

PERIOD_S = 0.004
FULL_EDGE_DEG = 20.0
LOOP_EDGE_DEG = 28.0
SHEET_KNOB = dataclasses.replace(DEVICE_KNOB, plateau_gap_deg=6.0, plateau_gap_factor=1.4)
GRID = (-90.0, 0.0, 90.0)


def synthetic_loop(full_edge_deg: float = FULL_EDGE_DEG, loop_edge_deg: float = LOOP_EDGE_DEG,
                   seed: int = 0) -> tuple[np.ndarray, ...]:
    """A knob's loop move (t, cmd, pos, current): friction with the sign of the speed, and on
    the way out a tension ramp from the edge: the full cycle's edge after a reversal at the
    other side's amplitude, the loop's after a reversal in the dead zone."""
    move = loop_move(0, PERIOD_S)
    pos = move.q_deg[:, 0]
    v = np.gradient(pos)
    current = np.zeros_like(pos)
    turned_at = 0.0
    for i in range(1, pos.size):
        if v[i] * v[i - 1] < 0 or (v[i - 1] == 0 and v[i] != 0):
            turned_at = pos[i]
        out = v[i] * pos[i] > 0 and (pos[i] * turned_at <= 0 or abs(pos[i]) > abs(turned_at))
        edge = loop_edge_deg if abs(turned_at) < 0.5 * LOOP_AMPLITUDE_DEG else full_edge_deg
        load = 0.004 * max(abs(pos[i]) - edge, 0.0) if out else 0.0
        current[i] = 0.03 * np.sign(v[i]) + np.sign(pos[i]) * load
    rng = np.random.default_rng(seed)
    return move.t_s, pos, pos, current + rng.normal(0.0, 0.001, pos.size)


def test_the_move_loops_each_side_into_the_dead_zone_and_crosses_once_each_way() -> None:
    assert loop_points(90.0, 2) == [0.0, -90.0, 0.0, -90.0, 0.0, -90.0, 90.0, 0.0, 90.0, 0.0,
                                    90.0, -90.0, 0.0]


def test_the_move_holds_the_other_knob_at_zero_and_ends_at_zero() -> None:
    move = loop_move(1, PERIOD_S)
    assert np.all(move.q_deg[:, 0] == 0.0)
    assert move.q_deg[-1, 1] == pytest.approx(0.0)
    assert np.max(np.abs(move.q_deg[:, 1])) == pytest.approx(LOOP_AMPLITUDE_DEG)


def test_a_current_with_known_loop_and_full_edges_gives_their_gap() -> None:
    edges = read_loop_edges(*synthetic_loop())
    assert len(edges.loop_pos_deg) == len(edges.loop_neg_deg) == 2
    assert len(edges.full_pos_deg) == len(edges.full_neg_deg) == 1
    assert edges.gap_deg == pytest.approx(LOOP_EDGE_DEG - FULL_EDGE_DEG, abs=0.5)


def test_a_wider_loop_reads_a_wider_gap() -> None:
    narrow = read_loop_edges(*synthetic_loop(loop_edge_deg=25.0)).gap_deg
    wide = read_loop_edges(*synthetic_loop(loop_edge_deg=31.0)).gap_deg
    assert wide - narrow == pytest.approx(6.0, abs=0.7)


def test_one_loops_outlying_edge_does_not_move_the_gap() -> None:
    edges = LoopEdges((28.0, 37.0), (-28.0, -28.0), (20.0,), (-20.0,))
    assert edges.gap_deg == pytest.approx(8.0)


def test_a_side_whose_loops_lie_inside_its_full_cycles_edge_is_no_reading() -> None:
    edges = LoopEdges((31.25, 31.0), (-31.5, -31.5), (19.5,), (-38.5,))
    assert edges.gap_deg == pytest.approx(11.625)


def test_no_edge_read_gives_no_gap() -> None:
    assert math.isnan(LoopEdges((math.nan,), (), (20.0,), ()).gap_deg)


def test_a_unit_whose_gap_is_the_sheets_keeps_its_heights_bit_for_bit() -> None:
    sweeps = [synthetic_sweep(g) for g in GRID]
    plain = fit_tension_play(sweeps, SHEET_KNOB)
    same = fit_tension_play(sweeps, SHEET_KNOB, plateau_gap_deg=6.0)
    assert same == plain


@pytest.mark.parametrize(("gap_deg", "sign"), [(8.0, 1), (4.5, -1)])
def test_a_wider_gap_moves_the_heights_apart_a_narrower_together(gap_deg: float,
                                                                  sign: int) -> None:
    sweeps = [synthetic_sweep(g) for g in GRID]
    plain = fit_tension_play(sweeps, SHEET_KNOB)
    moved = fit_tension_play(sweeps, SHEET_KNOB, plateau_gap_deg=gap_deg)
    shift = 0.5 * 1.4 * (gap_deg - 6.0)
    assert sign * shift > 0
    assert moved.height_pos_deg == pytest.approx(plain.height_pos_deg - shift)
    assert moved.height_neg_deg == pytest.approx(plain.height_neg_deg + shift)
    assert moved.dead_zone_pos_deg == plain.dead_zone_pos_deg
    assert moved.level_grid == plain.level_grid


def test_a_sheet_without_the_loop_fields_changes_nothing() -> None:
    sweeps = [synthetic_sweep(g) for g in GRID]
    assert fit_tension_play(sweeps, DEVICE_KNOB, plateau_gap_deg=9.0) == fit_tension_play(
        sweeps, DEVICE_KNOB)
    assert plateau_shift_deg(9.0, None, None) == 0.0


def test_only_a_sheet_with_both_loop_numbers_plays_the_loop() -> None:
    half = dataclasses.replace(DEVICE_KNOB, plateau_gap_deg=6.0)
    assert not wants_loop(DeviceModel("x", (DEVICE_KNOB, DEVICE_KNOB)))
    assert not wants_loop(DeviceModel("x", (half, DEVICE_KNOB)))
    assert wants_loop(DeviceModel("x", (DEVICE_KNOB, SHEET_KNOB)))


def test_the_sheets_flats_are_the_tip_where_each_way_in_ends() -> None:
    move = loop_move(0, PERIOD_S)
    cmd = move.q_deg[:, 0]
    # a tip resting at +7 after a way in from +A, -5 after one from -A
    tip = np.zeros_like(cmd)
    side = 0.0
    for i in range(cmd.size):
        side = np.sign(cmd[i]) if abs(cmd[i]) > LOOP_AMPLITUDE_DEG - 1e-6 else side
        tip[i] = 7.0 if side > 0 else -5.0
    assert tracked_flats(cmd, tip) == pytest.approx((7.0, 5.0))


def test_the_sheets_factor_is_both_flats_over_the_gap() -> None:
    assert SheetLoop(8.0, 5.0, 6.0).factor == pytest.approx(11.0 / 8.0)
    assert math.isnan(SheetLoop(math.nan, 5.0, 6.0).factor)
    assert math.isnan(SheetLoop(8.0, -1.0, 6.0).factor)


def test_the_sheets_loop_numbers_round_trip_and_are_range_checked() -> None:
    assert_sheet_knob_field_round_trips("plateau_gap_deg", 1, 8.6, 60.0)
    assert_sheet_knob_field_round_trips("plateau_gap_factor", 0, 1.35, 20.0)


class _SyntheticRig:
    """A runner whose swept knob shows :func:`synthetic_loop`'s current (the other knob's is
    friction-free and flat); ``stop_after`` ticks: it stops there as a faulted run would."""

    period_s = PERIOD_S

    def __init__(self, stop_after: int | None = None) -> None:
        self.stop_after = stop_after
        self.runs: list[np.ndarray] = []

    def run(self, t_s: np.ndarray, q_deg: np.ndarray, compensate: bool,
            cancel: object = None, progress: object = None) -> Recording:
        q = np.asarray(q_deg, float)
        self.runs.append(q)
        n = len(q) if self.stop_after is None else min(self.stop_after, len(q))
        knob = int(np.argmax(np.ptp(q, axis=0))) if np.ptp(q) > 0 else 0
        columns = {"t": np.asarray(t_s, float)[:n]}
        for k in (0, 1):
            cur = (synthetic_loop()[3] if k == knob and len(q) == len(loop_move(0, PERIOD_S).q_deg)
                   else np.zeros(len(q)))
            columns.update({f"cmd{k + 1}": q[:n, k], f"pos{k + 1}": q[:n, k],
                            f"cur{k + 1}": cur[:n]})
        return Recording(columns)


def test_the_calibration_plays_the_loop_of_an_opted_in_knob_only_and_reads_its_gap() -> None:
    rig = _SyntheticRig()
    run = play_loops(rig, DeviceModel("x", (DEVICE_KNOB, SHEET_KNOB)), None)  # type: ignore[arg-type]
    assert run.gaps_deg[0] is None
    assert run.gaps_deg[1] == pytest.approx(LOOP_EDGE_DEG - FULL_EDGE_DEG, abs=0.5)
    assert len(rig.runs) == 1 and np.all(rig.runs[0][:, 0] == 0.0)
    assert "phi2: plateau gap" in run.notes[0]


def test_a_loop_cut_short_is_refused_with_the_knobs_sent_back_to_zero() -> None:
    rig = _SyntheticRig(stop_after=1000)
    with pytest.raises(CalibrationError, match="dead-zone loop phi1: the runner stopped"):
        play_loops(rig, DeviceModel("x", (SHEET_KNOB, DEVICE_KNOB)), None)  # type: ignore[arg-type]
    assert rig.runs[-1][-1] == pytest.approx([0.0, 0.0])
