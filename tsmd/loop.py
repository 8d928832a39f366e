"""The control loop: one :meth:`ControlLoop.tick` per period, owned by a single thread.

A tick reads the drives' feedback, takes the latest setpoint (or the next sample of a
trajectory being played), clamps it into the knob limits, compensates it (the compensator sees
both knobs, so each knob's dead zone and backlash follow the other knob's angle), applies the
rate/position limiter last, writes the targets, sends SYNC and records the row.

Nothing else touches the drives: the API thread posts :class:`LoopCommand` objects that the
loop executes between ticks, and reads :attr:`ControlLoop.latest_sample`, which the loop
replaces atomically each tick. Who calls :meth:`tick` decides the time base: the real-time
scheduler (:mod:`tsmd.rt`) on the monotonic clock, or a lockstep driver on the rig's SimClock.
"""

from __future__ import annotations

import collections
import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from drivers.clock import Clock
from drivers.drive import DriveError, FaultEvent, KnobDrives
from tsmd.compensation import Compensator
from tsmd.compensation.safety import MAX_TICK_PERIODS, KnobLimiter, KnobLimits
from tsmd.loop_commands import LoopCommands
from tsmd.loop_compensators import LoopCompensators
from tsmd.loop_recorders import BackgroundRecorder, MemoryRecorder
from tsmd.loop_supervision import tick_fault
from tsmd.loop_types import (
    ROW,
    ROW_COLUMNS,
    LatestSetpoint,
    LoopCommand,
    LoopError,
    LoopState,
    LoopStats,
    Playback,
    Sample,
    TickRecorder,
)

__all__ = [
    "ROW_COLUMNS", "BackgroundRecorder", "ControlLoop", "LatestSetpoint", "LoopCommand",
    "LoopError", "LoopState", "LoopStats", "MemoryRecorder", "Playback", "Sample", "TickRecorder",
]

_isfinite = math.isfinite
Pair = tuple[float, float]
_ENABLED = LoopState.ENABLED  # read several times a tick: a global, not an enum class lookup
_pack_row = ROW.pack


class ControlLoop(LoopCommands):
    """Fixed-period feed-forward control of the knob drives; see the module docstring.

    ``standby``: the compensator(s) that may be switched on mid-run for the same catheter,
    which follow the motor while not active (:mod:`tsmd.loop_compensators`). The commands
    executed between ticks are :class:`tsmd.loop_commands.LoopCommands`.
    """

    def __init__(self, drives: KnobDrives, compensator: Compensator, limiter: KnobLimiter,
                 period_s: float, clock: Clock, *,
                 stale_feedback_syncs: int = 3, overrun_fault_streak: int = 5,
                 compensation_label: str = "none",
                 tip_source: Callable[[], Any] | None = None,
                 after_sync: Callable[[], None] | None = None,
                 recorder: TickRecorder | None = None,
                 on_event: Callable[..., None] | None = None,
                 standby: Mapping[str, Compensator] | None = None) -> None:
        if drives.count != 2:
            raise ValueError(f"the loop drives two knobs, got {drives.count} drives")
        self.drives = drives
        self.period_s = period_s
        self.clock = clock
        self.stale_feedback_syncs = stale_feedback_syncs
        self.overrun_fault_streak = overrun_fault_streak
        self._compensators = LoopCompensators(compensator, compensation_label, standby)
        self._limiter = limiter
        if limiter.dt_s != period_s:
            raise ValueError(f"the limiter steps {limiter.dt_s} s, the loop {period_s} s")
        self._min = np.array([r.min_deg for r in limiter.limits], dtype=float)
        self._max = np.array([r.max_deg for r in limiter.limits], dtype=float)
        self._min_f = tuple(float(v) for v in self._min)
        self._max_f = tuple(float(v) for v in self._max)
        self._tip_source = tip_source
        self._after_sync = after_sync
        self.recorder = recorder
        self._on_event = on_event
        self.setpoint = LatestSetpoint()
        self.commands: collections.deque[LoopCommand] = collections.deque()
        self.max_pending_commands = 64
        self.state = LoopState.DISABLED
        self.fault_reason: str | None = None
        self.stats = LoopStats()
        self._latest: tuple[int, float, LoopState, tuple[float, ...], str | None] | None = None
        self._sample_cache: tuple[object, Sample] | None = None
        self.last_events: collections.deque[FaultEvent] = collections.deque(maxlen=16)
        self.schedule_reset = False
        """Set after a command that blocked (enable): the scheduler re-anchors its deadlines."""
        self._playback: Playback | None = None
        self.observer: Callable[[tuple[float, ...], bool], None] | None = None
        """Called with each tick's row and whether the loop is enabled (tsmd.online)."""
        self._q: Pair = (0.0, 0.0)
        """The last desired angles, clamped (floats: the hot path makes no arrays)."""
        self._last_cmd: Pair = (0.0, 0.0)
        self._play_q: list[list[float]] = []
        """The playing trajectory as Python floats (converted once, not per tick)."""
        self._nan2 = (math.nan, math.nan)
        self._t_prev_s: float | None = None
        self._carry_s = 0.0
        self.dt_s = period_s
        """The time this tick counts for, in whole periods (the period when it was on time):
        what the compensators and the limiter are given."""

    # --- configuration read by the API -----------------------------------------------------

    @property
    def compensation_label(self) -> str:
        return self._compensators.label

    @property
    def playing(self) -> bool:
        """True while a trajectory (a calibration sweep) owns the setpoint."""
        return self._playback is not None

    def ranges(self) -> tuple[KnobLimits, ...]:
        """The knobs' limits: setpoints are clamped into them, commands limited by them."""
        return self._limiter.limits

    # --- the tick --------------------------------------------------------------------------

    @property
    def latest_sample(self) -> Sample | None:
        """What the last tick did (built on demand: most ticks are never looked at)."""
        latest = self._latest
        if latest is None:
            return None
        cache = self._sample_cache
        if cache is not None and cache[0] is latest:
            return cache[1]
        sample = Sample.from_row(*latest)
        self._sample_cache = (latest, sample)
        return sample

    def tick(self) -> Sample:
        """One period (:meth:`step`) and what it did."""
        self.step()
        sample = self.latest_sample
        assert sample is not None  # step() always publishes one
        return sample

    def step(self) -> None:
        """One period: commands, supervision, setpoint, compensation, targets, SYNC, record."""
        if self.commands:
            self._run_commands()
        drives = self.drives
        t_s = self.clock.now_s()
        self.dt_s = self._elapsed_s(t_s)
        drives.pump()
        events = drives.poll_events()
        feedback = drives.feedback()
        pos = [feedback[0].position_deg, feedback[1].position_deg]
        if events:
            self.last_events.extend(events)
        if self.state is _ENABLED:
            reason = tick_fault(events, feedback, self.stale_feedback_syncs,
                                self.stats.overrun_streak, self.overrun_fault_streak)
            if reason is not None:
                self._fault(reason)
        if self.state is _ENABLED:
            q, cmd = self._command(pos)
        else:
            q = cmd = ((pos[0], pos[1]) if _isfinite(pos[0]) and _isfinite(pos[1])
                       else self._last_cmd)
        c0, c1 = cmd
        if _isfinite(c0) and _isfinite(c1):
            self._last_cmd = cmd
        drives.write_targets((c0, c1))
        drives.sync()
        if self._after_sync is not None:
            self._after_sync()
            drives.pump()
            feedback = drives.feedback()
        tip = (self._tip_source() if self._tip_source is not None else self._nan2)
        if isinstance(tip, np.ndarray) and tip.dtype == np.float64 and tip.shape == (2,):
            tip0, tip1 = tip.tolist()
        else:
            tip0, tip1 = float(tip[0]), float(tip[1])
        q0, q1 = q
        fb0, fb1 = feedback
        row = (t_s, q0, q1, c0, c1, fb0.position_deg, fb1.position_deg,
               fb0.current_A, fb1.current_A, tip0, tip1)
        self._record(row)
        if self.observer is not None:
            self.observer(row, self.state is _ENABLED)
        self.stats.ticks += 1
        self._latest = (self.stats.ticks, t_s, self.state, row, self.fault_reason)

    def _elapsed_s(self, t_s: float) -> float:
        """The time since the last tick began, in whole periods (at least one, at most
        :data:`MAX_TICK_PERIODS`), the remainder carried to the next tick: a tick woken late and
        the next one woken on time are two periods and one, not 1.7 and 0.3 (the drives take a
        target per SYNC, and ours steps its limits and average per period). On time, and in
        lockstep, it is exactly the period; a clock that did not advance gives the period."""
        prev, self._t_prev_s = self._t_prev_s, t_s
        period = self.period_s
        if prev is None or not t_s - prev > 0.0:
            return period
        carry = self._carry_s + (t_s - prev)
        n = int(carry / period + 0.5)
        if n > MAX_TICK_PERIODS:  # a stall: what it missed is no motion time
            self._carry_s = 0.0
            return MAX_TICK_PERIODS * period
        n = n if n > 1 else 1
        carry -= n * period
        self._carry_s = carry if carry > -period else -period
        return period if n == 1 else n * period

    def _command(self, pos: list[float]) -> tuple[Pair, Pair]:
        playback = self._playback
        compensator: Compensator | None = self._compensators.active
        if playback is not None:
            if playback.cancel is not None and playback.cancel.is_set():
                self._end_playback("cancelled")
                q_raw: Any = self._q
            else:
                q_raw = self._play_q[playback.index]
                if not playback.compensate:
                    compensator = None  # the desired angles as they are
                else:  # a compensator that can use what comes next sees the plan this tick
                    preview = getattr(compensator, "preview", None)
                    if preview is not None:
                        preview(self._play_q, playback.index)
        else:
            q_raw = self.setpoint.get()
        if q_raw is None:
            q_raw = self._q
        q0, q1 = float(q_raw[0]), float(q_raw[1])
        if not (_isfinite(q0) and _isfinite(q1)):
            self._fault(f"non-finite setpoint {[q0, q1]}")
            return self._q, self._last_cmd
        lo, hi = self._min_f, self._max_f
        q = (min(max(q0, lo[0]), hi[0]), min(max(q1, lo[1]), hi[1]))
        self._q = q
        if compensator is None:
            c0, c1 = q
        else:
            cmd = np.asarray(compensator.command(np.array(q), self.dt_s), dtype=float)
            if cmd.shape != (2,) or not (_isfinite(cmd[0]) and _isfinite(cmd[1])):
                self._fault(f"compensator gave {cmd.tolist()} for q {list(q)}")
                return q, self._last_cmd
            c0, c1 = cmd.tolist()
        # one SYNC, one period of the limits whatever the tick's lateness: a CSP drive moves to
        # each target over its interpolation period (0x60C2), so a larger step would be a
        # faster move than the velocity limit (the compensator still counts the elapsed time)
        c0, c1 = self._limiter.limit_pair(c0, c1)
        if not (_isfinite(c0) and _isfinite(c1)):
            self._fault(f"limiter gave {[c0, c1]} for q {list(q)}")
            return q, self._last_cmd
        c0, c1 = min(max(c0, lo[0]), hi[0]), min(max(c1, lo[1]), hi[1])
        self._compensators.follow(q[0], q[1], c0, c1, self.dt_s)
        return q, (c0, c1)

    def _record(self, row: tuple[float, ...]) -> None:
        if self.recorder is not None:
            self.recorder.append(row)
        playback = self._playback
        if playback is not None and self.state is _ENABLED:
            playback.rows += _pack_row(*row)
            playback.index += 1
            if playback.index >= len(playback.q_deg):
                self._end_playback(None)

    def _end_playback(self, error: str | None) -> None:
        playback = self._playback
        if playback is None:
            return
        self._playback = None
        self._play_q = []
        playback.error = error
        self.setpoint.set(self._q)
        # The held setpoint is the last desired angle; after an uncompensated sweep that is a
        # knob angle, not where the tip is: at rest there, or the compensator would move the
        # knobs on its own to bring the tip to it.
        self._compensators.active.reset(np.array(self._q))
        playback.done.set()

    # --- faults ----------------------------------------------------------------------------

    def note_overrun(self, overran: bool) -> None:
        """Called by the scheduler after each tick: counts overruns and their streak."""
        if overran:
            self.stats.overruns += 1
            self.stats.overrun_streak += 1
        else:
            self.stats.overrun_streak = 0

    def _fault(self, reason: str) -> None:
        """Quick stop, state FAULT with the reason (once per fault)."""
        if self.state is LoopState.FAULT:
            return
        self.state = LoopState.FAULT
        self.fault_reason = reason
        self.stats.faults += 1
        try:
            self.drives.quick_stop()
        except DriveError as exc:
            reason = f"{reason}; quick stop failed: {exc}"
            self.fault_reason = reason
        self._end_playback(f"fault: {reason}")
        self.setpoint.clear()
        self._emit("error", "fault", reason=reason)

    def _emit(self, level: str, event: str, **fields: Any) -> None:
        if self._on_event is not None:
            self._on_event(level, event, **fields)
