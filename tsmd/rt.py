"""Real-time set-up of the calling thread: SCHED_FIFO, CPU affinity, locked memory.

Each step is attempted separately; what the system refuses (no CAP_SYS_NICE, no RLIMIT_RTPRIO,
a container) becomes a warning in the returned report, never an error: the loop still runs,
with worse latency, and the benchmark shows by how much.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import math
import os
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

MCL_CURRENT = 1
MCL_FUTURE = 2


@dataclass
class RealtimeReport:
    """What was applied and what was refused (with the reason)."""

    fifo_priority: int | None = None
    cpu: int | None = None
    memory_locked: bool = False
    warnings: list[str] = field(default_factory=list)


def set_fifo(priority: int) -> str | None:
    """SCHED_FIFO at ``priority`` for the calling thread; the reason on failure."""
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except (OSError, AttributeError) as exc:
        return f"SCHED_FIFO priority {priority} refused ({_reason(exc)})"
    return None


def set_normal_scheduling() -> str | None:
    """SCHED_OTHER for the calling thread (and whatever it starts from now on)."""
    try:
        os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
    except (OSError, AttributeError) as exc:
        return f"SCHED_OTHER refused ({_reason(exc)})"
    return None


@contextmanager
def fifo_scheduling(priority: int) -> Iterator[str | None]:
    """SCHED_FIFO at ``priority`` for the calling thread inside the block, the normal scheduler
    after it; yields the reason it was refused (then nothing changed), or None."""
    refused = set_fifo(priority)
    try:
        yield refused
    finally:
        if refused is None:
            set_normal_scheduling()


def set_affinity(cpu: int) -> str | None:
    try:
        os.sched_setaffinity(0, {cpu})
    except (OSError, AttributeError) as exc:
        return f"pinning to CPU {cpu} refused ({_reason(exc)})"
    return None


def lock_memory() -> str | None:
    """mlockall(MCL_CURRENT | MCL_FUTURE) through libc."""
    name = ctypes.util.find_library("c")
    if name is None:
        return "mlockall unavailable (no libc found)"
    libc = ctypes.CDLL(name, use_errno=True)
    if libc.mlockall(MCL_CURRENT | MCL_FUTURE) != 0:
        err = ctypes.get_errno()
        return f"mlockall refused ({os.strerror(err)})"
    return None


def apply_realtime(priority: int, cpu: int | None, lock: bool) -> RealtimeReport:
    """Apply the configured real-time settings to the calling thread."""
    report = RealtimeReport()
    if lock:
        problem = lock_memory()
        if problem is None:
            report.memory_locked = True
        else:
            report.warnings.append(problem)
    if cpu is not None:
        problem = set_affinity(cpu)
        if problem is None:
            report.cpu = cpu
        else:
            report.warnings.append(problem)
    if priority > 0:
        problem = set_fifo(priority)
        if problem is None:
            report.fifo_priority = priority
        else:
            report.warnings.append(problem)
    return report


def _reason(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    return str(exc)


CLOCK_MONOTONIC = 1
TIMER_ABSTIME = 1


class _Timespec(ctypes.Structure):
    _fields_ = [("tv_sec", ctypes.c_long), ("tv_nsec", ctypes.c_long)]


class AbsoluteSleeper:
    """Sleeps until an absolute time on CLOCK_MONOTONIC (clock_nanosleep, TIMER_ABSTIME).

    Absolute deadlines do not accumulate the drift that relative sleeps do; ``time.monotonic``
    reads the same clock. Falls back to ``time.sleep`` where libc lacks clock_nanosleep.
    """

    def __init__(self) -> None:
        name = ctypes.util.find_library("c")
        self._fn = None
        if name is not None:
            libc = ctypes.CDLL(name, use_errno=True)
            fn = getattr(libc, "clock_nanosleep", None)
            if fn is not None:
                fn.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.POINTER(_Timespec),
                               ctypes.c_void_p]
                fn.restype = ctypes.c_int
                self._fn = fn
        self._ts = _Timespec()

    def sleep_until(self, deadline_s: float) -> None:
        if self._fn is None:
            delay = deadline_s - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            return
        frac, whole = math.modf(deadline_s)
        self._ts.tv_sec = int(whole)
        self._ts.tv_nsec = int(frac * 1e9)
        while self._fn(CLOCK_MONOTONIC, TIMER_ABSTIME, ctypes.byref(self._ts), None) == 4:
            pass  # EINTR: a signal arrived; sleep on to the same deadline


@dataclass
class TickTimes:
    """Per-tick timing kept in preallocated ring buffers (no allocation on the hot path)."""

    capacity: int
    lateness_s: NDArray[np.float64] = field(init=False)
    start_s: NDArray[np.float64] = field(init=False)
    cpu_s: NDArray[np.float64] = field(init=False)
    count: int = 0
    overruns: int = 0
    missed_deadlines: int = 0

    def __post_init__(self) -> None:
        self.lateness_s = np.zeros(self.capacity)
        self.start_s = np.zeros(self.capacity)
        self.cpu_s = np.zeros(self.capacity)

    def add(self, start_s: float, lateness_s: float, cpu_s: float) -> None:
        i = self.count % self.capacity
        self.start_s[i] = start_s
        self.lateness_s[i] = lateness_s
        self.cpu_s[i] = cpu_s
        self.count += 1

    def clear(self) -> None:
        """Forget what was measured so far (a benchmark's warm-up)."""
        self.count = self.overruns = self.missed_deadlines = 0

    def _ordered(self, a: NDArray[np.float64]) -> NDArray[np.float64]:
        if self.count <= self.capacity:
            return a[: self.count].copy()
        i = self.count % self.capacity
        return np.concatenate([a[i:], a[:i]])

    def lateness(self) -> NDArray[np.float64]:
        return self._ordered(self.lateness_s)

    def starts(self) -> NDArray[np.float64]:
        return self._ordered(self.start_s)

    def cpu(self) -> NDArray[np.float64]:
        return self._ordered(self.cpu_s)


class FixedRateScheduler:
    """Calls ``tick()`` at absolute deadlines ``t0 + k * period`` on the monotonic clock.

    A tick that ends after the next deadline is an overrun; the deadlines it covered are
    skipped (never bunched up to catch up), and ``on_overrun(bool)`` is told after every tick.
    """

    def __init__(self, period_s: float, tick: Callable[[], object], *,
                 on_tick_end: Callable[[bool], None] | None = None,
                 should_reanchor: Callable[[], bool] | None = None,
                 history: int = 1 << 16) -> None:
        self.period_s = period_s
        self._tick = tick
        self._on_tick_end = on_tick_end
        self._should_reanchor = should_reanchor
        self.times = TickTimes(history)
        self._sleeper = AbsoluteSleeper()

    def run(self, stop: threading.Event, max_ticks: int | None = None) -> None:
        period = self.period_s
        deadline = time.monotonic() + period
        n = 0
        while not stop.is_set() and (max_ticks is None or n < max_ticks):
            self._sleeper.sleep_until(deadline)
            start = time.monotonic()
            cpu0 = time.thread_time()
            self._tick()
            end = time.monotonic()
            self.times.add(start, start - deadline, time.thread_time() - cpu0)
            n += 1
            deadline += period
            if self._should_reanchor is not None and self._should_reanchor():
                deadline = end + period
                overran = False
            else:
                overran = end > deadline
                if overran:
                    self.times.overruns += 1
                    missed = math.ceil((end - deadline) / period)
                    self.times.missed_deadlines += missed
                    deadline += missed * period
            if self._on_tick_end is not None:
                self._on_tick_end(overran)
