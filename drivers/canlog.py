"""Every frame a bus sends and receives, handed to python-can listeners (e.g. ``can.Logger``).

A :class:`can.Notifier` would own the bus's receive side in a thread of its own; the daemon's
control loop instead polls its bus from the loop thread (one thread touching the bus, none
competing with the loop for the GIL). :class:`TappedBus` keeps that: it is a ``can.BusABC``
around the real bus that passes each frame the caller sends or receives to its listeners, in
the caller's thread.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import can


class TappedBus(can.BusABC):
    """``bus`` with each sent and received frame also given to ``listeners``."""

    def __init__(self, bus: can.BusABC, listeners: Sequence[can.Listener], **kwargs: Any) -> None:
        super().__init__(channel=bus.channel_info, **kwargs)
        self.inner = bus
        self.listeners = list(listeners)
        self.channel_info = f"tapped {bus.channel_info}"

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        self.inner.send(msg, timeout)
        for listener in self.listeners:
            listener.on_message_received(msg)

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        msg = self.inner.recv(timeout)  # the inner bus has applied its own filters already
        if msg is not None:
            for listener in self.listeners:
                listener.on_message_received(msg)
        return msg, True

    def shutdown(self) -> None:
        try:
            for listener in self.listeners:
                listener.stop()
        finally:
            self.inner.shutdown()
            super().shutdown()
