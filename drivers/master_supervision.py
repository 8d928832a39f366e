"""Supervision of the bus and the drives: the receive path, fault events, bus events.

Every frame the master receives goes through :meth:`MasterSupervision._on_message`: TPDOs update
the drive images, heartbeats and EMCYs are watched, SocketCAN error frames become
:class:`drivers.can_errors.BusEvent` (bus-off also a fault), unknown COB-IDs are reported once.
:meth:`MasterSupervision._supervise` turns silence into ``HEARTBEAT_LOST`` / ``STALE_FEEDBACK``.
"""

from __future__ import annotations

import collections
import math
import struct
import threading
import time
from collections.abc import Callable
from typing import Any

import can

from drivers import cia402
from drivers import od as o
from drivers.can_errors import BusEvent, BusState, decode_error_frame
from drivers.clock import Clock
from drivers.drive import DriveState, FaultEvent, FaultKind
from drivers.drive_image import TPDO, DriveImage
from drivers.units import MasterTimeouts

_EMCY = struct.Struct("<HB5s")
_NMT_NAMES = {0x00: "boot-up", 0x04: "STOPPED", 0x05: "OPERATIONAL", 0x7F: "PRE-OPERATIONAL"}
MAX_PENDING_BUS_EVENTS = 256
"""Error frames can flood (a broken wire): older bus events are dropped and counted."""


class MasterSupervision:
    """The receive path and the fault/bus event queues of :class:`CanOpenDrives`."""

    # Set by CanOpenDrives.__init__; declared here for the layers that use them.
    bus: can.BusABC
    period_s: float
    interpolation: tuple[int, int]
    clock: Clock
    idle: Callable[[], None] | None
    master_node_id: int
    master_heartbeat_s: float
    timeouts: MasterTimeouts
    bus_state: BusState
    bus_events_dropped: int
    frames_sent: int
    frames_received: int
    syncs_sent: int
    _od: Any
    _drives: list[DriveImage]
    _events: list[FaultEvent]
    _bus_events: collections.deque[BusEvent]
    _unknown_ids: set[int]
    _send_failing: bool
    _recv_failing: bool
    _sync_msg: can.Message
    _hb_msg: can.Message
    _next_heartbeat_s: float | None
    _handlers: dict[int, Callable[[bytearray], None]]
    _queue: collections.deque[can.Message] | None
    _lock: threading.Lock

    def _on_message(self, msg: can.Message) -> None:
        self.frames_received += 1
        if msg.is_error_frame:
            self._on_error_frame(msg)
            return
        handler = self._handlers.get(msg.arbitration_id)
        if handler is None or msg.is_extended_id or msg.is_remote_frame:
            self._unknown(msg)
            return
        handler(msg.data)

    def _tpdo_handler(self, d: DriveImage) -> Callable[[bytearray], None]:
        unpack = TPDO.unpack
        size = TPDO.size
        decode = cia402.decode_state

        def on_tpdo(data: bytearray) -> None:
            if len(data) != size:
                self._event(FaultKind.BUS_ERROR, d.index,
                            f"{d.name}: malformed TPDO1 0x{0x180 + d.node_id:03X} with "
                            f"{len(data)} bytes, its mapping (0x6041, 0x6064, 0x6078) needs "
                            f"{size}")
                return
            sw, d.position_counts, d.current_raw = unpack(data)
            d.age_syncs = 0
            d.has_feedback = True
            d.stale_reported = False
            if sw != d.statusword:
                d.statusword = sw
                state = decode(sw)
                if state is DriveState.FAULT and d.state is not DriveState.FAULT:
                    self._event(FaultKind.DRIVE_FAULT, d.index,
                                f"{d.name}: drive entered FAULT ({self._emcy_text(d)})",
                                d.last_emcy)
                d.state = state

        return on_tpdo

    def _heartbeat_handler(self, d: DriveImage) -> Callable[[bytearray], None]:
        def on_heartbeat(data: bytearray) -> None:
            if len(data) != 1:
                self._event(FaultKind.BUS_ERROR, d.index,
                            f"{d.name}: malformed heartbeat with {len(data)} bytes")
                return
            state = data[0] & 0x7F
            if state == 0x00 and d.supervised:
                self._on_reboot(d)
                return
            if d.supervised and state != 0x05 and d.nmt_state == 0x05:
                self._event(FaultKind.DRIVE_FAULT, d.index,
                            f"{d.name}: left OPERATIONAL, NMT state is now "
                            f"{_NMT_NAMES.get(state, hex(state))}")
            d.nmt_state = state
            d.last_heartbeat_s = self.clock.now_s()
            d.heartbeat_lost = False

        return on_heartbeat

    def _emcy_handler(self, d: DriveImage) -> Callable[[bytearray], None]:
        def on_emcy(data: bytearray) -> None:
            if len(data) != 8:
                self._event(FaultKind.BUS_ERROR, d.index,
                            f"{d.name}: malformed EMCY with {len(data)} bytes")
                return
            code, register, _ = _EMCY.unpack(data)
            if code == 0:
                d.last_emcy = None
                return
            d.last_emcy = code
            self._event(FaultKind.EMCY, d.index,
                        f"{d.name}: EMCY 0x{code:04X} {o.emcy_meaning(code)} "
                        f"(error register 0x{register:02X})", code)

        return on_emcy

    def _on_reboot(self, d: DriveImage) -> None:
        """A boot-up from a running drive: it lost power or reset, and with it its PDO mapping,
        its parameters and (relative encoder) its zero reference."""
        d.rebooted = True
        d.supervised = False
        d.has_feedback = False
        d.homed = False
        d.nmt_state = 0x00
        d.state = DriveState.UNKNOWN
        d.controlword = 0
        d.last_heartbeat_s = self.clock.now_s()
        self._event(FaultKind.DRIVE_REBOOTED, d.index,
                    f"{d.name}: rebooted while running (boot-up message): parameters, PDO "
                    f"mapping and zero reference lost; it stays without torque until a reset "
                    f"re-configures it")

    def _on_error_frame(self, msg: can.Message) -> None:
        report = decode_error_frame(msg)
        previous = self.bus_state
        if report.state is not None:
            self.bus_state = report.state
        text = report.text()
        with self._lock:
            if len(self._bus_events) == self._bus_events.maxlen:
                self.bus_events_dropped += 1
            self._bus_events.append(BusEvent(self.clock.now_s(), report, text))
        if report.bus_off and previous is not BusState.BUS_OFF:
            for d in self._drives:  # the first frames after a restart must not move anything
                d.controlword = cia402.CW_QUICK_STOP
            self._event(FaultKind.BUS_OFF, -1,
                        f"CAN controller bus-off ({text}): nothing can be sent until the "
                        f"interface restarts; the drives quick-stop on the lost master heartbeat")

    def poll_bus_events(self) -> list[BusEvent]:
        """Error frames decoded since the last call (warnings, restarts...), oldest first.

        Only bus-off is a fault (a ``BUS_OFF`` :class:`FaultEvent`); the rest is for the log.
        """
        with self._lock:
            events = list(self._bus_events)
            self._bus_events.clear()
        return events

    def _unknown(self, msg: can.Message) -> None:
        cob = msg.arbitration_id
        if cob in self._unknown_ids:
            return
        self._unknown_ids.add(cob)
        self._event(FaultKind.BUS_ERROR, -1,
                    f"unexpected CAN frame 0x{cob:03X} ({len(msg.data)} bytes"
                    f"{', extended id' if msg.is_extended_id else ''}"
                    f"{', remote' if msg.is_remote_frame else ''}): no configured drive "
                    f"object uses this COB-ID")

    def _supervise(self) -> None:
        now = self.clock.now_s()
        for d in self._drives:
            if not d.supervised:
                continue
            last = d.last_heartbeat_s
            if (not d.heartbeat_lost and last is not None
                    and now - last > d.config.heartbeat_timeout_ms * 1e-3):
                d.heartbeat_lost = True
                self._event(FaultKind.HEARTBEAT_LOST, d.index,
                            f"{d.name}: no heartbeat for {now - last:.3f} s "
                            f"(timeout {d.config.heartbeat_timeout_ms} ms)")
            if d.age_syncs >= d.config.stale_after_syncs and not d.stale_reported:
                d.stale_reported = True
                self._event(FaultKind.STALE_FEEDBACK, d.index,
                            f"{d.name}: TPDO not refreshed by the last {d.age_syncs} SYNCs")

    def _on_bus_error(self, exc: Exception) -> None:
        """Notifier thread: receiving failed. One event per run of failures, then throttle."""
        if not self._recv_failing:
            self._recv_failing = True
            self._event(FaultKind.BUS_ERROR, -1, f"CAN receive failed in the notifier: {exc}")
        time.sleep(0.01)  # a dead adapter fails every call: do not spin a core on it

    def _event(self, kind: FaultKind, drive: int, message: str, code: int | None = None) -> None:
        event = FaultEvent(kind=kind, drive=drive, t_s=self.clock.now_s(), message=message,
                           code=code)
        with self._lock:
            self._events.append(event)

    def poll_events(self) -> list[FaultEvent]:
        with self._lock:
            events, self._events = self._events, []
        return events

    def heartbeat_lost(self) -> list[bool]:
        with self._lock:
            return [d.heartbeat_lost for d in self._drives]

    def _silent_since(self, d: DriveImage, start_s: float) -> bool:
        """No TPDO answered a SYNC and no heartbeat arrived since ``start_s``."""
        last_hb = d.last_heartbeat_s
        return (not d.has_feedback or d.age_syncs > 0) and (last_hb is None or last_hb < start_s)

    def _silence_s(self, d: DriveImage) -> float:
        last = d.last_heartbeat_s
        return self.clock.now_s() - last if last is not None else math.inf

    @staticmethod
    def _emcy_text(d: DriveImage) -> str:
        if d.last_emcy is None:
            return "no EMCY received"
        return f"EMCY 0x{d.last_emcy:04X} {o.emcy_meaning(d.last_emcy)}"


class QueueListener(can.Listener):
    """Notifier thread -> deque; errors of the receive thread become BUS_ERROR events."""

    def __init__(self, queue: collections.deque[can.Message],
                 on_error: Callable[[Exception], None]) -> None:
        self._queue = queue
        self._on_error = on_error

    def on_message_received(self, msg: can.Message) -> None:
        self._queue.append(msg)

    def on_error(self, exc: Exception) -> None:
        self._on_error(exc)
