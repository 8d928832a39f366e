"""One client connection of the API server, and the small policies applied per connection.

Kept apart from :mod:`tsmd.api.server` (the socket, accepting, reading lines) so handlers can
import what a connection offers (replies, streams, tasks) without the server.
"""

from __future__ import annotations

import asyncio
import time
from collections.abc import Awaitable, Iterable
from typing import Any

from tsmd.api.protocol import encode

STREAM_HIGH_WATER_BYTES = 64 * 1024
DRAIN_TIMEOUT_S = 5.0


class Connection:
    """One client: replies in order, optional streams that drop when the client is slow."""

    def __init__(self, writer: asyncio.StreamWriter) -> None:
        self.writer = writer
        self.tasks: dict[str, asyncio.Task[Any]] = {}
        self.dropped = 0
        self.closed = False
        self.last_request_s = time.monotonic()
        """When the last complete request arrived (or the connection was accepted)."""

    @property
    def streaming(self) -> bool:
        """A stream or a long command still runs for this client: it is not idle."""
        return any(not t.done() for t in self.tasks.values())

    @property
    def calibrating(self) -> bool:
        return any(name.startswith("calibrate:") and not t.done()
                   for name, t in self.tasks.items())

    async def reply(self, message: dict[str, Any]) -> None:
        if self.closed:
            return
        self.writer.write(encode(message))
        try:
            await asyncio.wait_for(self.writer.drain(), DRAIN_TIMEOUT_S)
        except (TimeoutError, ConnectionError):
            self.close()

    def send_event(self, message: dict[str, Any]) -> bool:
        """Stream one event without waiting; dropped (and counted) if the client lags."""
        if self.closed:
            return False
        transport = self.writer.transport
        if transport.is_closing() or transport.get_write_buffer_size() > STREAM_HIGH_WATER_BYTES:
            self.dropped += 1
            return False
        self.writer.write(encode(message))
        return True

    def start_task(self, name: str, coro: Awaitable[Any]) -> None:
        self.cancel_task(name)
        self.tasks[name] = asyncio.ensure_future(coro)

    def cancel_task(self, name: str) -> bool:
        task = self.tasks.pop(name, None)
        if task is None:
            return False
        task.cancel()
        return True

    def close(self) -> None:
        if self.closed:
            return
        self.closed = True
        for name in list(self.tasks):
            self.cancel_task(name)
        self.writer.close()


class TokenBucket:
    """Requests (or accepts) per second with a burst; the caller sleeps what it is told."""

    def __init__(self, rate_per_s: float, burst: float) -> None:
        self.rate = rate_per_s
        self.burst = burst
        self.tokens = burst
        self.t = time.monotonic()

    def wait_s(self) -> float:
        """Take one token; how long to wait first when none is left."""
        now = time.monotonic()
        self.tokens = min(self.burst, self.tokens + (now - self.t) * self.rate)
        self.t = now
        self.tokens -= 1.0
        return 0.0 if self.tokens >= 0 else -self.tokens / self.rate


def least_active(connections: Iterable[Connection]) -> Connection | None:
    """The client to evict for a newcomer: idle before streaming, longest since a request.

    A client running a calibration is never chosen (closing it would cancel the calibration).
    """
    candidates = [c for c in connections if not c.closed and not c.calibrating]
    if not candidates:
        return None
    return min(candidates, key=lambda c: (c.streaming, c.last_request_s))
