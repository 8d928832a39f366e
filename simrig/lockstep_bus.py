"""An in-process python-can bus for lockstep simulation: no threads, no copies beyond the data.

python-can's ``virtual`` bus deep-copies every frame into a thread-safe queue, which costs more
than all of a tick's CANopen logic. Lockstep runs are single-threaded by design, so this bus
hands each peer a fresh :class:`can.Message` with its own data bytes through a plain deque.
It behaves like ``virtual`` otherwise: buses on the same channel name see each other's frames,
not their own. Use ``virtual`` (or a real interface) for anything threaded.
"""

from __future__ import annotations

import collections
import time
from typing import Any

import can

from drivers.can_errors import CAN_ERR_BUSOFF, CAN_ERR_RESTARTED

_CHANNELS: dict[str, list[LockstepBus]] = {}
_MESSAGE_SLOTS = {"__weakref__", "arbitration_id", "bitrate_switch", "channel", "data", "dlc",
                  "error_state_indicator", "is_error_frame", "is_extended_id", "is_fd",
                  "is_remote_frame", "is_rx", "timestamp"}
_new_message = can.Message.__new__


def _make_message(can_id: int, data: bytes | bytearray, extended: bool = False,
                  remote: bool = False, error: bool = False) -> can.Message:
    """A received-frame ``Message`` without the constructor's argument checks (3x faster)."""
    msg = _new_message(can.Message)
    msg.timestamp = 0.0
    msg.arbitration_id = can_id
    msg.is_extended_id = extended
    msg.is_remote_frame = remote
    msg.is_error_frame = error
    msg.channel = None
    msg.is_fd = False
    msg.is_rx = True
    msg.bitrate_switch = False
    msg.error_state_indicator = False
    msg.data = bytearray(data)
    msg.dlc = len(data)
    return msg


def _checked_message(can_id: int, data: bytes | bytearray, extended: bool = False,
                     remote: bool = False, error: bool = False) -> can.Message:
    return can.Message(arbitration_id=can_id, data=data, is_extended_id=extended,
                       is_remote_frame=remote, is_error_frame=error, check=False)


# python-can may add fields one day: then fall back to its constructor
make_message = (_make_message if set(getattr(can.Message, "__slots__", ())) == _MESSAGE_SLOTS
                else _checked_message)


class LockstepBus(can.BusABC):
    """A ``virtual``-like bus for one thread; ``recv`` with a timeout only sleeps-and-polls."""

    def __init__(self, channel: str, **kwargs: Any) -> None:
        super().__init__(channel=channel, **kwargs)
        self.channel_info = f"lockstep channel {channel!r}"
        self._name = channel
        self._queue: collections.deque[can.Message] = collections.deque()
        self._peers = _CHANNELS.setdefault(channel, [])
        self._peers.append(self)
        self._open = True
        self._bus_off = False

    def set_bus_off(self, on: bool) -> None:
        """Simulate this controller going bus-off (nothing in or out) or being restarted.

        Like SocketCAN, the change is announced by an error frame (bus-off, restarted).
        """
        self._bus_off = on
        if on:
            self._queue.clear()
        self._queue.append(make_message(CAN_ERR_BUSOFF if on else CAN_ERR_RESTARTED,
                                        bytes(8), error=True))

    def others(self) -> list[LockstepBus]:
        """The other buses on this channel (the rig reaches the master's controller here)."""
        return [peer for peer in self._peers if peer is not self]

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        if not self._open:
            raise can.CanOperationError(f"lockstep bus {self._name!r} is shut down")
        if self._bus_off:
            raise can.CanOperationError(f"lockstep bus {self._name!r}: controller is bus-off")
        data = msg.data
        for peer in self._peers:
            if peer is not self and not peer._bus_off:
                peer._queue.append(make_message(msg.arbitration_id, data, msg.is_extended_id,
                                                msg.is_remote_frame, msg.is_error_frame))

    def send_owned(self, msg: can.Message) -> None:
        """Send a frame the caller will never touch again: peers get the object itself."""
        if not self._open:
            raise can.CanOperationError(f"lockstep bus {self._name!r} is shut down")
        for peer in self._peers:
            if peer is not self and not peer._bus_off:
                peer._queue.append(msg)

    def recv(self, timeout: float | None = None) -> can.Message | None:
        queue = self._queue
        if queue:
            return queue.popleft()
        if not timeout:
            return None
        deadline = time.monotonic() + timeout
        while not queue:
            if time.monotonic() >= deadline:
                return None
            time.sleep(0.0002)
        return queue.popleft()

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        return self.recv(timeout), True

    def shutdown(self) -> None:
        if self._open:
            self._open = False
            self._peers.remove(self)
            if not self._peers:
                _CHANNELS.pop(self._name, None)
        super().shutdown()
