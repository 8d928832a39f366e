"""The ``calibrate`` handler: a calibration never outlives the request that started it."""

from __future__ import annotations

import asyncio
import threading
from collections.abc import Callable
from types import SimpleNamespace
from typing import Any

from tsmd.api.handlers import ApiHandlers
from tsmd.api.protocol import Request


class BlockingService:
    """Stands in for tsmd.service.Service: a calibration that runs until it is cancelled."""

    def __init__(self) -> None:
        self.started = threading.Event()
        self.cancel: threading.Event | None = None

    def calibrate(self, catheter: str, progress: Callable[[dict[str, Any]], None],
                  cancel: threading.Event) -> dict[str, Any]:
        self.cancel = cancel
        self.started.set()
        cancel.wait(10.0)
        return {"profile": catheter}


def open_connection() -> Any:
    """A connection whose transport stays open: only the task's cancellation says it is gone."""
    transport = SimpleNamespace(is_closing=lambda: False)
    return SimpleNamespace(closed=False, writer=SimpleNamespace(transport=transport),
                           send_event=lambda message: True)


def test_cancelling_the_request_task_cancels_the_calibration_at_once() -> None:
    """What the server does when a client's connection ends: close() cancels its tasks."""
    service = BlockingService()
    handlers = ApiHandlers(service)  # type: ignore[arg-type]

    async def scenario() -> None:
        request = Request("calibrate", "c", {"catheter": "cath-y"})
        task = asyncio.ensure_future(handlers(request, open_connection()))
        while not service.started.is_set():
            await asyncio.sleep(0.01)
        task.cancel()
        await asyncio.gather(task, return_exceptions=True)

    asyncio.run(scenario())
    assert service.cancel is not None and service.cancel.is_set()
