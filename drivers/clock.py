"""Clocks: the master's supervision and the simulated rig read time only through these."""

from __future__ import annotations

import time
from typing import Protocol


class Clock(Protocol):
    """A monotonic time source in seconds."""

    def now_s(self) -> float: ...


class MonotonicClock:
    """Wall time on the monotonic clock, for the real robot and real-time simulation."""

    def now_s(self) -> float:
        return time.monotonic()


class SimClock:
    """Simulated time that only moves when told to (lockstep runs, tests, replay)."""

    def __init__(self, start_s: float = 0.0) -> None:
        self._t_s = start_s

    def now_s(self) -> float:
        return self._t_s

    def advance(self, dt_s: float) -> None:
        if dt_s < 0:
            raise ValueError(f"simulated time cannot go back (dt_s={dt_s})")
        self._t_s += dt_s
