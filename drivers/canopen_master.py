"""CANopen master for CiA 402 knob drives in Cyclic Synchronous Position mode.

Per tick it sends one RPDO per drive (controlword + target position) and a SYNC; each drive
answers with one TPDO (statusword + position actual + current actual): 5 frames for two drives.

The cyclic path and the SDO client (:mod:`drivers.sdo`) are our own and never block on another
thread: frames are read by :meth:`CanOpenDrives.pump`, either straight from the bus
(``receive="poll"``, lockstep and deterministic) or from a python-can ``Notifier`` queue
(``receive="notifier"``, real time). While boot and the state machine wait for an answer they
call the ``idle`` hook (the simulated rig's ``exchange`` in lockstep) or sleep a little in real
time. canopen supplies the object dictionary (our EDS) used to encode SDO values.
"""

from __future__ import annotations

import collections
import threading
from collections.abc import Callable, Sequence
from typing import Literal

import can

from drivers import od as o
from drivers.can_errors import BusEvent, BusState
from drivers.clock import Clock, MonotonicClock
from drivers.drive import DriveError, FaultEvent, KnobDrives
from drivers.drive_image import DriveImage
from drivers.master_boot import MOTOR_SPEED_HEADROOM
from drivers.master_homing import MasterHoming
from drivers.master_supervision import MAX_PENDING_BUS_EVENTS, QueueListener
from drivers.sdo import SdoClient
from drivers.units import DriveConfig, MasterTimeouts, interpolation_period

__all__ = ["MAX_PENDING_BUS_EVENTS", "MOTOR_SPEED_HEADROOM", "CanOpenDrives"]


class CanOpenDrives(MasterHoming, KnobDrives):
    """N CiA 402 drives on one python-can bus (``socketcan``/``can0`` or ``virtual``).

    Its parts, one concept per module: the drive image (:mod:`drivers.drive_image`), the receive
    path and supervision (:mod:`drivers.master_supervision`), the cyclic exchange and SDO
    (:mod:`drivers.master_exchange`), boot (:mod:`drivers.master_boot`), the state machine
    (:mod:`drivers.master_states`) and homing (:mod:`drivers.master_homing`).
    """

    def __init__(
        self,
        bus: can.BusABC,
        configs: Sequence[DriveConfig],
        period_s: float,
        *,
        clock: Clock | None = None,
        idle: Callable[[], None] | None = None,
        receive: Literal["poll", "notifier"] = "poll",
        master_node_id: int = 127,
        master_heartbeat_ms: int = 50,
        timeouts: MasterTimeouts | None = None,
        own_bus: bool = False,
    ) -> None:
        if not configs:
            raise DriveError("no drives configured")
        ids = [c.node_id for c in configs]
        if len(set(ids)) != len(ids) or master_node_id in ids:
            raise DriveError(f"node ids must be unique and differ from the master's "
                             f"({master_node_id}): {ids}")
        self.bus = bus
        self.period_s = period_s
        self.interpolation = interpolation_period(period_s)
        self.clock: Clock = clock if clock is not None else MonotonicClock()
        self.idle = idle
        self.master_node_id = master_node_id
        self.master_heartbeat_s = master_heartbeat_ms * 1e-3
        self.timeouts = timeouts if timeouts is not None else MasterTimeouts()
        self._own_bus = own_bus
        self._od = o.load_od()
        self._drives = [DriveImage(i, c) for i, c in enumerate(configs)]
        for d in self._drives:
            d.sdo = SdoClient(d.node_id, d.name, self._send, self._wait, self.clock,
                              self.timeouts.sdo_s)
        self._events: list[FaultEvent] = []
        self.bus_state = BusState.ERROR_ACTIVE
        """Our controller's state as its error frames announce it (SocketCAN)."""
        self._bus_events: collections.deque[BusEvent] = collections.deque(
            maxlen=MAX_PENDING_BUS_EVENTS)
        self.bus_events_dropped = 0
        self._unknown_ids: set[int] = set()
        self._send_failing = False
        self._recv_failing = False
        self._sync_msg = can.Message(arbitration_id=0x080, is_extended_id=False, data=b"")
        self._hb_msg = can.Message(arbitration_id=0x700 + master_node_id, is_extended_id=False,
                                   data=bytes((0x05,)))
        self._next_heartbeat_s: float | None = None
        self.frames_sent = 0
        self.frames_received = 0
        self.syncs_sent = 0
        self._handlers: dict[int, Callable[[bytearray], None]] = {}
        for d in self._drives:
            self._handlers[0x180 + d.node_id] = self._tpdo_handler(d)
            self._handlers[0x700 + d.node_id] = self._heartbeat_handler(d)
            self._handlers[0x080 + d.node_id] = self._emcy_handler(d)
            self._handlers[0x580 + d.node_id] = d.sdo.on_response
        # before the notifier starts: its thread reports a failing bus through the lock at once
        self._lock = threading.Lock()
        self._queue: collections.deque[can.Message] | None = None
        self._notifier: can.Notifier | None = None
        if receive == "notifier":
            self._queue = collections.deque()
            self._notifier = can.Notifier(bus, [QueueListener(self._queue, self._on_bus_error)],
                                          timeout=0.05)
        elif receive != "poll":
            raise DriveError(f"receive must be 'poll' or 'notifier', not {receive!r}")

    @classmethod
    def open(cls, interface: str, channel: str, configs: Sequence[DriveConfig], period_s: float,
             bitrate: int = 1_000_000, **kwargs: object) -> CanOpenDrives:
        """Open a python-can bus (e.g. ``socketcan``/``can0``) and the master on it."""
        try:
            bus = can.Bus(interface=interface, channel=channel, bitrate=bitrate)
        except (can.CanError, OSError, ValueError, ImportError) as exc:
            raise DriveError(f"cannot open CAN interface {interface!r} channel {channel!r}: "
                             f"{exc}") from exc
        kwargs.setdefault("receive", "notifier")
        return cls(bus, configs, period_s, own_bus=True, **kwargs)  # type: ignore[arg-type]

    def close(self) -> None:
        if self._notifier is not None:
            self._notifier.stop()
            self._notifier = None
        if self._own_bus:
            self.bus.shutdown()
