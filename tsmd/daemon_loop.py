"""The loop thread a daemon runs: the fixed-rate scheduler under the configured real-time
settings, started (READY only once it ticks), watched (its death stops the daemon) and summed up.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from drivers.drive import DriveError
from tsmd.config import RealtimeConfig
from tsmd.errors import DaemonError
from tsmd.loop import ControlLoop
from tsmd.rt import FixedRateScheduler, RealtimeReport, apply_realtime


@dataclass
class RunSummary:
    ticks: int
    overruns: int
    faults: int
    lateness_p99_ms: float
    lateness_max_ms: float
    state: str
    fault: str | None


class LoopThread:
    """Ticks ``loop`` on its own thread; ``on_death(exc)`` when the loop raises (after a quick
    stop of the drives), so the daemon can shut down instead of holding dead drives."""

    def __init__(self, loop: ControlLoop, realtime: RealtimeConfig,
                 on_death: Callable[[BaseException], None]) -> None:
        self.loop = loop
        self.realtime = realtime
        self.on_death = on_death
        self.scheduler = FixedRateScheduler(loop.period_s, loop.tick,
                                            on_tick_end=loop.note_overrun,
                                            should_reanchor=self._reanchor)
        self.rt_report: RealtimeReport | None = None
        self.error: BaseException | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def _reanchor(self) -> bool:
        """After a command that blocked (enable, homing): new deadlines, no overrun counted."""
        loop = self.loop
        if loop.schedule_reset:
            loop.schedule_reset = False
            return True
        return False

    def start(self, timeout_s: float = 5.0) -> None:
        """Start the thread and return once the loop has ticked (DaemonError otherwise)."""
        started = threading.Event()
        rt = self.realtime
        loop = self.loop

        def run() -> None:
            self.rt_report = apply_realtime(rt.priority, rt.cpu, rt.lock_memory)
            started.set()
            try:
                self.scheduler.run(self._stop)
            except BaseException as exc:  # the loop died: make it visible, then stop
                self.error = exc
                with contextlib.suppress(DriveError):
                    loop.drives.quick_stop()
                self.on_death(exc)

        self._thread = threading.Thread(target=run, name="tsmd-loop", daemon=True)
        self._thread.start()
        started.wait(timeout_s)
        deadline = time.monotonic() + timeout_s
        while loop.latest_sample is None and time.monotonic() < deadline:
            time.sleep(loop.period_s)  # READY means the loop is ticking
        if loop.latest_sample is None:
            raise DaemonError("the control loop did not start ticking", "loop")

    @property
    def alive(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def stop(self, timeout_s: float = 5.0) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout_s)

    def summary(self) -> RunSummary:
        loop = self.loop
        late = self.scheduler.times.lateness()
        return RunSummary(
            ticks=loop.stats.ticks, overruns=loop.stats.overruns, faults=loop.stats.faults,
            lateness_p99_ms=float(np.percentile(late, 99) * 1e3) if late.size else 0.0,
            lateness_max_ms=float(late.max() * 1e3) if late.size else 0.0,
            state=loop.state.value, fault=loop.fault_reason)
