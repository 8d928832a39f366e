"""The control loop's tick: setpoint -> limits -> compensation -> targets, and its faults."""

from __future__ import annotations

import numpy as np
import pytest
from support.drives import FakeDrives

from drivers.clock import SimClock
from drivers.drive import DriveState
from tsmd.compensation.safety import MAX_TICK_PERIODS, KnobLimiter, KnobLimits
from tsmd.loop import ControlLoop, LoopError, LoopState, MemoryRecorder, Playback

PERIOD_S = 0.004
LIMITS = [KnobLimits(-90.0, 90.0, 120.0, 2000.0)] * 2


class Offset:
    """A toy compensator: adds a constant, remembers its calls."""

    def __init__(self, offset_deg: float = 5.0) -> None:
        self.offset_deg = offset_deg
        self.inputs: list[np.ndarray] = []
        self.resets: list[np.ndarray] = []
        self.dts: list[float] = []

    def reset(self, q_deg: np.ndarray) -> None:
        self.resets.append(np.array(q_deg))

    def command(self, q_deg: np.ndarray, dt_s: float) -> np.ndarray:
        self.inputs.append(np.array(q_deg))
        self.dts.append(dt_s)
        return np.asarray(q_deg) + self.offset_deg


def make_loop(comp: Offset | None = None, **kwargs: object) -> tuple[ControlLoop, FakeDrives]:
    drives = FakeDrives()
    clock = SimClock()
    loop = ControlLoop(drives, comp or Offset(0.0), KnobLimiter(LIMITS, PERIOD_S), PERIOD_S, clock,
                       after_sync=lambda: clock.advance(PERIOD_S), recorder=MemoryRecorder(),
                       **kwargs)  # type: ignore[arg-type]
    return loop, drives


def test_disabled_loop_holds_the_actual_position_and_keeps_syncing() -> None:
    loop, drives = make_loop()
    drives.pos = [12.0, -3.0]
    for _ in range(3):
        sample = loop.tick()
    assert sample.state is LoopState.DISABLED
    assert drives.targets[-1] == (12.0, -3.0)
    assert len(drives.targets) == 3


def test_enable_holds_position_then_follows_the_setpoint_through_the_compensator() -> None:
    comp = Offset(5.0)
    loop, drives = make_loop(comp)
    drives.pos = [10.0, 0.0]
    loop.tick()
    assert loop.execute("enable") == "ENABLED"
    assert np.allclose(comp.resets[-1], [10.0, 0.0])
    loop.setpoint.set((20.0, -10.0))
    for _ in range(200):
        loop.tick()
    assert np.allclose(comp.inputs[-1], [20.0, -10.0])
    assert np.allclose(drives.targets[-1], [25.0, -5.0])


def test_setpoint_is_clamped_to_the_knob_range_before_compensation() -> None:
    comp = Offset(0.0)
    loop, _ = make_loop(comp)
    loop.tick()
    loop.execute("enable")
    loop.setpoint.set((500.0, -500.0))
    loop.tick()
    assert np.allclose(comp.inputs[-1], [90.0, -90.0])


def test_command_respects_velocity_and_position_limits() -> None:
    loop, drives = make_loop(Offset(30.0))
    loop.tick()
    loop.execute("enable")
    loop.setpoint.set((90.0, -90.0))
    for _ in range(600):
        loop.tick()
    t = drives.targets_array()
    assert t.max() <= 90.0 and t.min() >= -90.0
    assert np.abs(np.diff(t, axis=0)).max() <= 120.0 * PERIOD_S + 1e-9


def test_every_tick_records_one_row_with_the_documented_columns() -> None:
    loop, _ = make_loop()
    recorder = loop.recorder
    assert isinstance(recorder, MemoryRecorder)
    for _ in range(5):
        loop.tick()
    assert len(recorder.rows) == 5
    assert all(len(row) == 11 for row in recorder.rows)
    assert recorder.rows[1][0] == pytest.approx(PERIOD_S)


def test_drive_fault_event_quick_stops_and_reports_fault() -> None:
    loop, drives = make_loop()
    loop.tick()
    loop.execute("enable")
    drives.emcy(1)
    sample = loop.tick()
    assert sample.state is LoopState.FAULT
    assert "emcy" in (sample.fault or "")
    assert "quick_stop" in drives.calls


def test_stale_feedback_is_a_fault() -> None:
    loop, drives = make_loop(stale_feedback_syncs=3)
    loop.tick()
    loop.execute("enable")
    drives.silent = True
    states = [loop.tick().state for _ in range(6)]
    assert states[-1] is LoopState.FAULT
    assert "stale" in (loop.fault_reason or "")


def test_streak_of_overruns_is_a_fault_but_isolated_overruns_are_not() -> None:
    loop, _ = make_loop(overrun_fault_streak=3)
    loop.tick()
    loop.execute("enable")
    for overran in (True, True, False, True, True, False):
        loop.note_overrun(overran)
        loop.tick()
    assert loop.state is LoopState.ENABLED
    for _ in range(3):
        loop.note_overrun(True)
    loop.tick()
    assert loop.state is LoopState.FAULT
    assert loop.stats.overruns == 7


def test_nan_command_from_the_compensator_is_a_fault_and_never_sent() -> None:
    comp = Offset(float("nan"))
    loop, drives = make_loop(comp)
    loop.tick()
    loop.execute("enable")
    loop.tick()
    assert loop.state is LoopState.FAULT
    assert np.all(np.isfinite(drives.targets_array()))


def test_reset_is_refused_while_the_cause_persists_and_recovers_after() -> None:
    loop, drives = make_loop()
    loop.tick()
    loop.execute("enable")
    drives.silent = True
    for _ in range(6):
        loop.tick()
    with pytest.raises(LoopError, match="stale"):
        loop.execute("reset")
    drives.silent = False
    loop.tick()
    assert loop.execute("reset") == "DISABLED"
    assert loop.execute("enable") == "ENABLED"


def test_enable_in_fault_is_refused() -> None:
    loop, drives = make_loop()
    loop.tick()
    loop.execute("enable")
    drives.emcy(0)
    loop.tick()
    with pytest.raises(LoopError, match="reset"):
        loop.execute("enable")


def test_stop_quick_stops_and_needs_enable_again() -> None:
    loop, drives = make_loop()
    loop.tick()
    loop.execute("enable")
    assert loop.execute("stop") == "DISABLED"
    assert drives.state is DriveState.QUICK_STOP_ACTIVE
    assert loop.setpoint.get() is None


def test_commands_posted_from_another_thread_run_at_the_next_tick() -> None:
    loop, _ = make_loop()
    future = loop.post("enable")
    assert not future.done()
    loop.tick()
    assert future.result(timeout=0) == "ENABLED"


def test_failed_enable_reports_the_drive_error() -> None:
    loop, drives = make_loop()
    drives.enable_fails = True
    with pytest.raises(LoopError, match="enable failed"):
        loop.execute("enable")
    assert loop.state is LoopState.DISABLED


def test_heartbeat_loss_faults_and_reset_waits_until_the_heartbeat_is_back() -> None:
    loop, drives = make_loop()
    loop.tick()
    loop.execute("enable")
    drives.lose_heartbeat(1)
    loop.tick()
    assert loop.state is LoopState.FAULT
    assert "heartbeat" in (loop.fault_reason or "")
    with pytest.raises(LoopError, match="no heartbeat"):
        loop.execute("reset")
    drives.heartbeat_missing[1] = False
    assert loop.execute("reset") == "DISABLED"


def test_a_fault_during_a_trajectory_ends_it_with_the_reason_and_clears_the_setpoint() -> None:
    loop, drives = make_loop()
    loop.tick()
    loop.execute("enable")
    playback = Playback(np.zeros((100, 2)), compensate=True)
    loop.execute("play", playback=playback)
    for _ in range(10):
        loop.tick()
    drives.emcy(0)
    loop.tick()
    assert playback.done.is_set()
    assert "emcy" in (playback.error or "")
    assert len(playback.table()) == 10
    assert loop.setpoint.get() is None


def test_an_uncompensated_trajectory_sends_the_desired_angles_past_the_compensator() -> None:
    comp = Offset(5.0)
    loop, _drives = make_loop(comp)
    loop.tick()
    loop.execute("enable")
    calls = len(comp.inputs)
    playback = Playback(np.zeros((4, 2)), compensate=False)
    loop.execute("play", playback=playback)
    while not playback.done.is_set():
        loop.tick()
    assert len(comp.inputs) == calls
    assert playback.table()[:, 3:5].tolist() == [[0.0, 0.0]] * 4


def test_latest_sample_is_the_last_tick_and_one_object_until_the_next() -> None:
    loop, drives = make_loop()
    assert loop.latest_sample is None
    drives.pos = [4.0, -2.0]
    returned = loop.tick()
    assert loop.latest_sample is loop.latest_sample
    assert loop.latest_sample == returned
    assert returned.tick == 1 and returned.pos_deg == (4.0, -2.0)
    loop.step()
    assert loop.latest_sample is not None and loop.latest_sample.tick == 2


class Previewing(Offset):
    """A toy compensator that also reads the plan."""

    def __init__(self) -> None:
        super().__init__(0.0)
        self.previews: list[tuple[float, int]] = []

    def preview(self, plan_deg: list[list[float]], index: int) -> None:
        self.previews.append((plan_deg[index][0], index))


def test_a_played_trajectory_is_previewed_every_tick_and_a_setpoint_never() -> None:
    comp = Previewing()
    loop, _drives = make_loop(comp)  # type: ignore[arg-type]
    loop.tick()
    loop.execute("enable")
    loop.setpoint.set((1.0, 0.0))
    loop.tick()
    assert comp.previews == []
    playback = Playback(np.column_stack([np.arange(5.0), np.zeros(5)]), compensate=True)
    loop.execute("play", playback=playback)
    while not playback.done.is_set():
        loop.tick()
    assert comp.previews == [(float(i), i) for i in range(5)]


def _enabled_on_a_sim_clock() -> tuple[Offset, ControlLoop]:
    """An enabled loop after one tick, on a SimClock that advances one period per SYNC."""
    comp = Offset(0.0)
    loop, _ = make_loop(comp)
    loop.tick()
    loop.execute("enable")
    loop.tick()
    assert isinstance(loop.clock, SimClock)
    return comp, loop


def test_the_compensator_is_given_the_time_since_the_last_tick() -> None:
    comp, loop = _enabled_on_a_sim_clock()
    loop.clock.advance(2 * PERIOD_S)  # two ticks missed
    loop.tick()
    loop.tick()
    assert comp.dts[-3:] == [PERIOD_S, pytest.approx(3 * PERIOD_S), PERIOD_S]


def test_a_late_tick_steps_the_drive_target_by_at_most_one_period_of_the_velocity_limit() -> None:
    loop, drives = make_loop(Offset(0.0))
    loop.tick()
    loop.execute("enable")
    loop.setpoint.set((80.0, 0.0))
    for _ in range(100):  # up to full speed
        loop.tick()
    before = drives.targets[-1][0]
    assert isinstance(loop.clock, SimClock)
    loop.clock.advance(2 * PERIOD_S)
    loop.tick()
    assert drives.targets[-1][0] - before == pytest.approx(PERIOD_S * 120.0)


def test_a_tick_woken_late_and_the_next_on_time_count_two_periods_and_one() -> None:
    comp, loop = _enabled_on_a_sim_clock()
    loop.clock.advance(0.7 * PERIOD_S)  # this tick wakes 0.7 periods late, the next on time
    loop.tick()
    loop.clock.advance(0.3 * PERIOD_S)
    loop.tick()
    loop.tick()
    assert comp.dts[-3:] == [pytest.approx(2 * PERIOD_S), PERIOD_S, PERIOD_S]


def test_a_stall_counts_for_at_most_the_longest_tick() -> None:
    comp, loop = _enabled_on_a_sim_clock()
    loop.clock.advance(0.5)
    loop.tick()
    loop.tick()
    assert comp.dts[-2:] == [pytest.approx(MAX_TICK_PERIODS * PERIOD_S), PERIOD_S]
