"""Logging with structlog: JSON lines for the journal, readable lines on a terminal.

The control loop never formats or writes a log line itself: it hands events to
:class:`EventLog`, whose queue is drained by a background thread, so a slow journal cannot
delay a tick.
"""

from __future__ import annotations

import logging
import queue
import sys
import threading
from typing import Any, Literal, TextIO

import structlog

LogFormat = Literal["auto", "json", "console"]


def configure_logging(fmt: LogFormat = "auto", level: str = "info",
                      stream: TextIO | None = None) -> None:
    """Configure structlog once for the process; ``auto`` picks console on a TTY, else JSON."""
    out = stream if stream is not None else sys.stderr
    if fmt == "auto":
        fmt = "console" if out.isatty() else "json"
    renderer: Any
    if fmt == "json":
        renderer = structlog.processors.JSONRenderer()
    else:
        renderer = structlog.dev.ConsoleRenderer(colors=out.isatty())
    structlog.configure(
        processors=[
            structlog.contextvars.merge_contextvars,
            structlog.processors.add_log_level,
            structlog.processors.TimeStamper(fmt="iso", utc=True),
            structlog.processors.format_exc_info,
            renderer,
        ],
        wrapper_class=structlog.make_filtering_bound_logger(
            logging.getLevelNamesMapping().get(level.upper(), logging.INFO)),
        logger_factory=structlog.PrintLoggerFactory(file=out),
        cache_logger_on_first_use=False,
    )


def get_logger(name: str = "tsmd") -> Any:
    return structlog.get_logger(name)


class EventLog:
    """A bounded hand-off from the hot path to the logger (drops and counts when full)."""

    def __init__(self, logger: Any | None = None, maxsize: int = 1024) -> None:
        self._log = logger if logger is not None else get_logger("tsmd.loop")
        self._queue: queue.Queue[tuple[str, str, dict[str, Any]] | None] = queue.Queue(maxsize)
        self.dropped = 0
        self._thread = threading.Thread(target=self._drain, name="tsmd-log", daemon=True)
        self._thread.start()

    def emit(self, level: str, event: str, **fields: Any) -> None:
        try:
            self._queue.put_nowait((level, event, fields))
        except queue.Full:
            self.dropped += 1

    def _drain(self) -> None:
        while True:
            item = self._queue.get()
            if item is None:
                return
            level, event, fields = item
            getattr(self._log, level, self._log.info)(event, **fields)

    def close(self, timeout_s: float = 2.0) -> None:
        """Write what is queued, then stop the thread."""
        try:
            self._queue.put(None, timeout=timeout_s)
        except queue.Full:
            return
        self._thread.join(timeout_s)
