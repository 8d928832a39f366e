"""The operator's record of the CAN bus: decoded error frames logged without flooding the log.

Bus-off also reaches the loop as a fault (``FaultKind.BUS_OFF``); the warnings, passive states
and restarts around it are only worth a log line each, and an error storm must not become
thousands of lines per second.
"""

from __future__ import annotations

import time
from typing import Any

from tsmd.log import EventLog

BUS_EVENT_LOG_PER_S = 5
"""At most this many CAN bus events logged per second."""


class RateLimitedLog:
    """Emits at most ``per_s`` lines per second; then one line counting what it left out."""

    def __init__(self, events: EventLog, per_s: int) -> None:
        self.events = events
        self.per_s = per_s
        self._window_s = time.monotonic()
        self._emitted = 0
        self.suppressed = 0

    def emit(self, level: str, event: str, **fields: Any) -> bool:
        now = time.monotonic()
        if now - self._window_s >= 1.0:
            self.flush()
            self._window_s = now
            self._emitted = 0
        if self._emitted >= self.per_s:
            self.suppressed += 1
            return False
        self._emitted += 1
        self.events.emit(level, event, **fields)
        return True

    def flush(self) -> None:
        if self.suppressed:
            self.events.emit("warning", "log lines suppressed (rate limit)",
                             count=self.suppressed)
            self.suppressed = 0


class BusEventLog(RateLimitedLog):
    """Reads ``drives.poll_bus_events()`` (backends without it have no bus) into the log."""

    def __init__(self, events: EventLog, per_s: int = BUS_EVENT_LOG_PER_S) -> None:
        super().__init__(events, per_s)

    def poll(self, drives: Any) -> int:
        poll = getattr(drives, "poll_bus_events", None)
        if poll is None:
            return 0
        events = poll()
        state = getattr(getattr(drives, "bus_state", None), "value", None)
        for event in events:
            self.emit("warning", "CAN bus event", message=event.message, bus_state=state)
        return len(events)
