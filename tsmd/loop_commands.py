"""The control loop's commands: what the API posts, executed between ticks in the loop thread.

:class:`LoopCommands` is the half of :class:`tsmd.loop.ControlLoop` that changes its state on
request (enable, disable, stop, reset, home, switch compensators, play, shut down); the tick
itself is in :mod:`tsmd.loop`. A command is named by its method ``_cmd_<name>``.
"""

from __future__ import annotations

import collections
from collections.abc import Callable, Mapping
from concurrent.futures import Future
from typing import Any

import numpy as np

from drivers.drive import DriveError, FaultEvent, KnobDrives
from tsmd.compensation import Compensator
from tsmd.compensation.safety import KnobLimiter
from tsmd.loop_compensators import LoopCompensators
from tsmd.loop_supervision import remaining_fault_cause, silent_drive
from tsmd.loop_types import (
    Array,
    LatestSetpoint,
    LoopCommand,
    LoopError,
    LoopState,
    LoopStats,
    Playback,
)

Pair = tuple[float, float]


class LoopCommands:
    """The command handlers of :class:`tsmd.loop.ControlLoop` (a mixin: the attributes below
    are the loop's)."""

    drives: KnobDrives
    commands: collections.deque[LoopCommand]
    max_pending_commands: int
    state: LoopState
    fault_reason: str | None
    stats: LoopStats
    setpoint: LatestSetpoint
    schedule_reset: bool
    stale_feedback_syncs: int
    last_events: collections.deque[FaultEvent]
    _compensators: LoopCompensators
    _limiter: KnobLimiter
    _min: Array
    _max: Array
    _q: Pair
    _last_cmd: Pair
    _playback: Playback | None
    _play_q: list[list[float]]
    _end_playback: Callable[[str | None], None]
    _emit: Callable[..., None]

    def post(self, name: str, **args: Any) -> Future[Any]:
        """Queue a command for the loop thread; raises LoopError('busy') when the queue is full."""
        command = LoopCommand(name, args)
        if len(self.commands) >= self.max_pending_commands:
            raise LoopError("busy", "the loop has too many pending commands")
        self.commands.append(command)  # deque.append is atomic: no lock on the hot path
        return command.future

    def execute(self, name: str, **args: Any) -> Any:
        """Run a command now, in the calling thread (only when no other thread ticks)."""
        return getattr(self, f"_cmd_{name}")(**args)

    def _run_commands(self) -> None:
        commands = self.commands
        while commands:
            command = commands.popleft()
            if not command.future.set_running_or_notify_cancel():
                continue
            try:
                result = self.execute(command.name, **command.args)
            except (LoopError, DriveError) as exc:
                command.future.set_exception(exc)
            except Exception as exc:  # a command must never kill the loop
                command.future.set_exception(LoopError("internal", f"{command.name}: {exc}"))
            else:
                command.future.set_result(result)

    def _hold_position(self) -> Array:
        pos = np.array([f.position_deg for f in self.drives.feedback()], dtype=float)
        if not np.all(np.isfinite(pos)):
            raise LoopError("feedback", f"no valid position feedback ({pos.tolist()})")
        return np.minimum(np.maximum(pos, self._min), self._max)

    def _cmd_enable(self) -> str:
        if self.state is LoopState.FAULT:
            raise LoopError("fault", f"in FAULT ({self.fault_reason}); send reset first")
        if self.state is LoopState.ENABLED:
            return self.state.value
        silent = silent_drive(self.drives)
        if silent is not None:
            raise LoopError("drive", f"{silent}; not enabling")
        self.schedule_reset = True
        try:
            self.drives.enable()
        except DriveError as exc:
            self._emit("warning", "enable failed", reason=str(exc))
            raise LoopError("drive", f"enable failed: {exc}") from None
        self.drives.pump()
        # Findings from while the drives were walked to OPERATION ENABLED (feedback late
        # during the walk) are history: enable() succeeded, so they are logged, not faults.
        for event in self.drives.poll_events():
            self.last_events.append(event)
            self._emit("warning", "drive event during enable", drive=event.drive,
                       kind=event.kind.value, message=event.message)
        pos = self._hold_position()
        self._q = self._last_cmd = (float(pos[0]), float(pos[1]))
        self._compensators.reset(pos)
        self._limiter.reset(pos)
        self.setpoint.set((float(pos[0]), float(pos[1])))
        self.stats.overrun_streak = 0
        self.state = LoopState.ENABLED
        self._emit("info", "enabled", position_deg=pos.tolist())
        return self.state.value

    def _cmd_disable(self) -> str:
        self.schedule_reset = True
        self._end_playback("disabled")
        self.drives.disable()
        self.setpoint.clear()
        if self.state is LoopState.ENABLED:
            self.state = LoopState.DISABLED
        self._emit("info", "disabled")
        return self.state.value

    def _cmd_stop(self) -> str:
        """Quick stop; the loop goes to DISABLED (enable again to move)."""
        self._end_playback("stopped")
        self.drives.quick_stop()
        self.setpoint.clear()
        if self.state is LoopState.ENABLED:
            self.state = LoopState.DISABLED
        self._emit("warning", "quick stop")
        return self.state.value

    def _cmd_reset(self) -> str:
        """Clear FAULT once its cause is gone; the loop is DISABLED afterwards."""
        if self.state is not LoopState.FAULT:
            return self.state.value
        self.schedule_reset = True
        self.drives.fault_reset()
        self.drives.disable()
        self.drives.pump()
        cause = remaining_fault_cause(self.drives, self.stale_feedback_syncs)
        if cause is not None:
            raise LoopError("fault", f"cause still present: {cause}")
        self.state = LoopState.DISABLED
        self.fault_reason = None
        self.stats.overrun_streak = 0
        self._emit("info", "fault reset")
        return self.state.value

    def _cmd_home(self, drives: list[int] | None = None) -> Any:
        """Find the knobs' zero reference (CiA 402 Homing Mode); only while DISABLED."""
        if self.state is not LoopState.DISABLED:
            raise LoopError("not_disabled", f"home: the loop is {self.state.value}; "
                                            "disable first")
        self.schedule_reset = True  # homing cycles the bus itself for seconds
        return self.drives.home(drives)

    def _cmd_set_compensator(self, compensator: Compensator, label: str,
                             standby: Mapping[str, Compensator] | None = None,
                             keep_state: bool = False) -> str:
        """Switch compensators between ticks. ``keep_state`` (the same catheter): each new one
        continues from the outgoing one of its method, which followed the motor if it was not
        active; otherwise (or without one) it starts at rest at the last desired angles."""
        self._compensators.switch(compensator, label, standby or {}, np.array(self._q),
                                  keep_state=keep_state)
        self._emit("info", "compensation", method=label)
        return label

    def _cmd_play(self, playback: Playback) -> None:
        if self.state is not LoopState.ENABLED:
            raise LoopError("not_enabled", f"cannot play a trajectory in state {self.state.value}")
        if self._playback is not None:
            raise LoopError("busy", "a trajectory is already playing")
        if playback.compensate:
            self._compensators.active.reset(np.array(self._q))
        self._play_q = np.asarray(playback.q_deg, dtype=float)[:, :2].tolist()
        self._playback = playback

    def _cmd_shutdown(self) -> str:
        """Quick stop then disable: what SIGTERM does."""
        self._end_playback("shutdown")
        if self.state is LoopState.ENABLED:
            try:
                self.drives.quick_stop()
            except DriveError as exc:
                self._emit("error", "quick stop failed", reason=str(exc))
        try:
            self.drives.disable()
        except DriveError as exc:
            self._emit("error", "disable failed", reason=str(exc))
        self.setpoint.clear()
        if self.state is LoopState.ENABLED:
            self.state = LoopState.DISABLED
        self._emit("info", "shutdown: drives quick-stopped and disabled")
        return self.state.value
