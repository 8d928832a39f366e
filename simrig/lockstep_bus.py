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


Frame = tuple[int, bytes, int]
"""A received frame as :meth:`LockstepBus.take_frames` gives it: COB-ID, data and flags
(0 for a plain data frame, else :data:`EXTENDED` | :data:`REMOTE` | :data:`ERROR`)."""
EXTENDED, REMOTE, ERROR = 1, 2, 4


def _flags(msg: can.Message) -> int:
    return ((EXTENDED if msg.is_extended_id else 0) | (REMOTE if msg.is_remote_frame else 0)
            | (ERROR if msg.is_error_frame else 0))


def as_frame(msg: can.Message) -> Frame:
    """A ``Message`` as the ``(cob_id, bytes, flags)`` tuple that
    :meth:`LockstepBus.take_frames` gives."""
    return msg.arbitration_id, bytes(msg.data), _flags(msg)


class LockstepBus(can.BusABC):
    """A ``virtual``-like bus for one thread; ``recv`` with a timeout only sleeps-and-polls.

    ``frames=True``: this end is read with :meth:`take_frames` (the simulated rig), so its
    peers queue a ``(cob_id, bytes, plain)`` tuple per frame instead of a ``Message`` copy;
    ``recv`` still works on it and builds the ``Message`` when asked.
    """

    def __init__(self, channel: str, *, frames: bool = False, **kwargs: Any) -> None:
        super().__init__(channel=channel, **kwargs)
        self.channel_info = f"lockstep channel {channel!r}"
        self._name = channel
        self._queue: collections.deque[can.Message] = collections.deque()
        self._frames: list[Frame] | None = [] if frames else None
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
            if self._frames is not None:
                self._frames.clear()
        self._deliver(make_message(CAN_ERR_BUSOFF if on else CAN_ERR_RESTARTED, bytes(8),
                                   error=True))

    def _deliver(self, msg: can.Message) -> None:
        """Queue a frame that nobody else holds."""
        if self._frames is not None:
            self._frames.append(as_frame(msg))
        else:
            self._queue.append(msg)

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
                frames = peer._frames
                if frames is not None:
                    plain = not (msg.is_extended_id or msg.is_remote_frame or msg.is_error_frame)
                    frames.append((msg.arbitration_id, bytes(data), 0 if plain else _flags(msg)))
                else:
                    peer._queue.append(make_message(msg.arbitration_id, data,
                                                    msg.is_extended_id, msg.is_remote_frame,
                                                    msg.is_error_frame))

    def send_owned(self, msg: can.Message) -> None:
        """Send a frame the caller will never touch again: peers get the object itself."""
        if not self._open:
            raise can.CanOperationError(f"lockstep bus {self._name!r} is shut down")
        for peer in self._peers:
            if peer is not self and not peer._bus_off:
                if peer._frames is None:
                    peer._queue.append(msg)
                else:
                    peer._frames.append(as_frame(msg))

    @property
    def reads_frames(self) -> bool:
        """Opened with ``frames=True``: read with :meth:`take_frames`."""
        return self._frames is not None

    def take_frames(self) -> list[Frame]:
        """Every frame received since the last call, oldest first (``frames=True`` ends)."""
        frames = self._frames
        if frames is None:
            raise RuntimeError("take_frames needs a bus opened with frames=True")
        if not frames:
            return frames
        self._frames = []
        return frames

    def recv(self, timeout: float | None = None) -> can.Message | None:
        queue = self._queue
        if queue:
            return queue.popleft()
        if self._frames:
            return self._pop_frame()
        if not timeout:
            return None
        deadline = time.monotonic() + timeout
        while not (queue or self._frames):
            if time.monotonic() >= deadline:
                return None
            time.sleep(0.0002)
        return queue.popleft() if queue else self._pop_frame()

    def _pop_frame(self) -> can.Message:
        """The oldest frame of a ``frames=True`` end as a ``Message`` (read the python-can way)."""
        assert self._frames
        cid, data, flags = self._frames.pop(0)
        return make_message(cid, data, bool(flags & EXTENDED), bool(flags & REMOTE),
                            bool(flags & ERROR))

    def _recv_internal(self, timeout: float | None) -> tuple[can.Message | None, bool]:
        return self.recv(timeout), True

    def shutdown(self) -> None:
        if self._open:
            self._open = False
            self._peers.remove(self)
            if not self._peers:
                _CHANNELS.pop(self._name, None)
        super().shutdown()
