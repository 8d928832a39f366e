"""A running API over a fake loop (no CAN, no physics) for the API tests.

:func:`start_stack` builds what the daemon builds for the API (loop, service, socket server,
scheduler thread) around :class:`support.drives.FakeDrives`.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from drivers.clock import MonotonicClock
from support.drives import FakeDrives
from tsmd.api.client import ApiClient
from tsmd.api.handlers import ApiHandlers
from tsmd.api.server import ApiServer
from tsmd.compensation.safety import KnobLimiter
from tsmd.config import TsmdConfig
from tsmd.loop import ControlLoop
from tsmd.rt import FixedRateScheduler
from tsmd.service import CompensationChoice, Service
from tsmd.stack import knob_limits, make_compensator

PERIOD_S = 0.004


@dataclass
class Stack:
    drives: FakeDrives
    loop: ControlLoop
    server: ApiServer
    path: Path
    stop: threading.Event
    thread: threading.Thread

    def client(self) -> ApiClient:
        return ApiClient(self.path, timeout_s=10.0)

    def wait_ticks(self, n: int) -> None:
        target = self.loop.stats.ticks + n
        deadline = time.monotonic() + 10.0
        while self.loop.stats.ticks < target and time.monotonic() < deadline:
            time.sleep(0.005)


def start_stack(tmp_path: Path, *, max_line_bytes: int = 4096, max_clients: int = 16,
                profiles_dir: Path | None = None) -> Stack:
    config = TsmdConfig()
    drives = FakeDrives()
    # The API tests exercise the socket protocol on a shared, often overloaded machine where a
    # 4 ms Python loop can miss five deadlines in a row; the overrun fault has its own tests
    # (tests/test_loop.py, tests/test_loop_supervision.py), so here it must not end a test.
    loop = ControlLoop(drives, make_compensator(None, "none", config),
                       KnobLimiter(knob_limits(config), PERIOD_S), PERIOD_S, MonotonicClock(),
                       overrun_fault_streak=1_000_000)
    service = Service(config, loop, None, CompensationChoice(True, "ours"),
                      profiles_dir=profiles_dir or tmp_path / "profiles")
    path = tmp_path / "run" / "tsmd.sock"
    server = ApiServer(path, ApiHandlers(service), max_line_bytes=max_line_bytes,
                       max_clients=max_clients)
    server.start()
    stop = threading.Event()
    scheduler = FixedRateScheduler(PERIOD_S, loop.tick, on_tick_end=loop.note_overrun)
    thread = threading.Thread(target=scheduler.run, args=(stop,), daemon=True)
    thread.start()
    stack = Stack(drives, loop, server, path, stop, thread)
    stack.wait_ticks(2)
    return stack



def stop_stack(stack: Stack) -> None:
    stack.stop.set()
    stack.thread.join(5)
    stack.server.stop()


def all_targets_inside_limits(drives: FakeDrives) -> bool:
    t = drives.targets_array()
    return bool(np.all(np.isfinite(t)) and t.min() >= -90.0 and t.max() <= 90.0)
