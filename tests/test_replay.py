"""Replay and the trajectory runners: full stack in lockstep, deterministic, faults surfaced."""

from __future__ import annotations

import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from tsmd.loop import LoopState
from tsmd.recording import REQUIRED_COLUMNS, Recording, read_recording
from tsmd.replay import LockstepRunner, ReplayError, carry_conditions, run_trajectory

PERIOD_S = 0.004


def sine(seconds: float = 2.0, amp_deg: float = 30.0) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0.0, seconds, 0.01)
    q = np.column_stack([amp_deg * np.sin(2 * np.pi * 0.5 * t),
                         0.5 * amp_deg * np.sin(2 * np.pi * t)])
    return t, q


def test_run_trajectory_records_every_tick_with_all_columns() -> None:
    t, q = sine(2.0)
    rec = run_trajectory(t, q)
    assert len(rec) == int(np.floor(t[-1] / PERIOD_S)) + 1
    assert all(c in rec.columns for c in REQUIRED_COLUMNS)
    assert np.allclose(np.diff(rec["t"]), PERIOD_S)
    assert np.allclose(rec["q1"], np.interp(rec["t"], t, q[:, 0]))
    assert rec.has_tip


def test_the_drives_follow_the_command_through_the_full_stack() -> None:
    t, q = sine(2.0)
    rec = run_trajectory(t, q)
    lag_err = np.abs(rec["pos1"][5:] - rec["cmd1"][5:])
    assert lag_err.max() < 2.0
    assert np.ptp(rec["pos1"]) > 50.0


def test_same_input_and_seed_give_identical_recordings() -> None:
    t, q = sine(1.0)
    a = run_trajectory(t, q, seed=3)
    b = run_trajectory(t, q, seed=3)
    for name in a.columns:
        assert np.array_equal(a[name], b[name], equal_nan=True), name


def test_replay_command_writes_the_same_file_twice(tmp_path: Path) -> None:
    t, q = sine(1.0)
    traj = tmp_path / "traj.csv"
    traj.write_text("t,q1,q2\n" + "".join(f"{a:.6f},{b:.6f},{c:.6f}\n" for a, b, c in
                                           zip(t, q[:, 0], q[:, 1], strict=True)))
    outs = []
    for name in ("a.csv", "b.csv"):
        out = tmp_path / name
        subprocess.run([sys.executable, "-m", "tsmd", "replay", "--sim", "--trajectory",
                        str(traj), "--out", str(out), "--no-compensation"], check=True,
                       capture_output=True, timeout=120)
        outs.append(out.read_bytes())
    assert outs[0] == outs[1]
    rec = read_recording(tmp_path / "a.csv")
    assert rec.metadata["compensation"] == "none"


def test_replay_of_a_bad_trajectory_file_is_one_line_error(tmp_path: Path) -> None:
    traj = tmp_path / "traj.csv"
    traj.write_text("t,q1,q2\n0,0,0\n0,1,1\n")
    proc = subprocess.run([sys.executable, "-m", "tsmd", "replay", "--sim", "--trajectory",
                           str(traj), "--out", str(tmp_path / "o.csv")], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 2
    assert "strictly increasing" in proc.stderr and "Traceback" not in proc.stderr


def test_bad_trajectory_arrays_are_refused() -> None:
    with pytest.raises(ReplayError, match="shape"):
        run_trajectory([0.0, 1.0], np.zeros((3, 2)))
    with pytest.raises(ReplayError, match="finite"):
        run_trajectory([0.0, 1.0], [[0.0, np.nan], [0.0, 0.0]])


def test_consecutive_runs_continue_from_where_the_knobs_are() -> None:
    with LockstepRunner() as runner:
        t = np.array([0.0, 1.0])
        first = runner.run(t, [[0.0, 0.0], [20.0, 0.0]], compensate=False)
        second = runner.run(t, [[20.0, 0.0], [20.0, 0.0]], compensate=False)
    assert first["pos1"][-1] == pytest.approx(20.0, abs=1.0)
    assert second["pos1"][0] == pytest.approx(20.0, abs=1.0)


def test_cancel_stops_the_trajectory_and_returns_what_was_recorded() -> None:
    cancel = threading.Event()

    def progress(fraction: float) -> None:
        if fraction > 0.3:
            cancel.set()

    t, q = sine(2.0)
    with LockstepRunner() as runner:
        rec = runner.run(t, q, compensate=False, cancel=cancel, progress=progress)
        assert runner.loop.state is LoopState.ENABLED
    assert 0.3 * 500 < len(rec) < 0.5 * 500
    assert rec.metadata["cancelled"] == "true"


@pytest.mark.parametrize(("kind", "expected"), [
    ("emcy", "emcy"),
    ("silent", "stale"),
    ("heartbeat_stop", "heartbeat"),
    ("following_error", ""),
])
def test_a_fault_injected_in_the_simulated_drive_quick_stops_the_run(kind: str,
                                                                     expected: str) -> None:
    t, q = sine(3.0, amp_deg=60.0)
    with LockstepRunner() as runner:
        def progress(fraction: float) -> None:
            if 0.2 < fraction < 0.25:
                runner.rig.inject_fault(kind, drive=1)

        with pytest.raises(ReplayError, match="fault") as exc:
            runner.run(t, q, compensate=False, progress=progress)
        assert runner.loop.state is LoopState.FAULT
        assert expected in str(exc.value).lower()
        assert expected in (runner.loop.fault_reason or "").lower()


def test_reset_recovers_after_the_injected_fault_is_cleared() -> None:
    t, q = sine(1.0)
    with LockstepRunner() as runner:
        runner.rig.inject_fault("emcy", drive=0)
        with pytest.raises(ReplayError):
            runner.run(t, q, compensate=False)
        runner.rig.clear_fault(0)
        runner.loop.tick()
        assert runner.loop.execute("reset") == "DISABLED"
        assert runner.loop.execute("enable") == "ENABLED"
        rec = runner.run(t, q, compensate=False)
    assert len(rec) == int(np.floor(t[-1] / PERIOD_S + 1e-9)) + 1


def test_a_played_recording_holds_the_rows_the_loop_recorded() -> None:
    from tsmd.loop import MemoryRecorder
    from tsmd.loop_types import ROW_COLUMNS

    t, q = sine(1.0)
    with LockstepRunner(seed=2) as runner:
        recorder = MemoryRecorder()
        runner.loop.recorder = recorder
        rec = runner.run(t, q, compensate=False)
    rows = np.array(recorder.rows)
    for j, name in enumerate(ROW_COLUMNS[1:], start=1):
        assert np.array_equal(rec[name], rows[:, j], equal_nan=True), name


def test_a_played_recording_has_contiguous_columns() -> None:
    t, q = sine(1.0)
    rec = run_trajectory(t, q)
    assert all(column.flags.c_contiguous for column in rec.columns.values())


def test_a_replayed_trajectory_carries_its_segment_labels_and_condition_headers() -> None:
    t, q = sine(1.0)
    label = np.where((t >= 0.3) & (t < 0.6), 0.0, -1.0)
    traj = Recording({"t": t, "q1": q[:, 0], "q2": q[:, 1], "segment": label},
                     {"segments": "rate:slow:0:-1", "configuration": "looped", "note": "x"})
    rec = run_trajectory(t, q)
    carry_conditions(traj, rec)
    # at 250 Hz the ticks between trajectory samples hold the label of the sample before
    expected = np.where((rec["t"] >= 0.3 - 1e-9) & (rec["t"] < 0.6 - 1e-9), 0.0, -1.0)
    assert np.array_equal(rec["segment"], expected)
    assert rec.metadata["segments"] == "rate:slow:0:-1"
    assert rec.metadata["configuration"] == "looped"
    assert "note" not in rec.metadata
