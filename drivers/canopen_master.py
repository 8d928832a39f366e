"""CANopen master for CiA 402 knob drives in Cyclic Synchronous Position mode.

Per tick it sends one RPDO per drive (controlword + target position) and a SYNC; each drive
answers with one TPDO (statusword + position actual + current actual): 5 frames for two drives.

The cyclic path and the SDO client (:mod:`drivers.sdo`) are our own and never block on another
thread: frames are
read by :meth:`CanOpenDrives.pump`, either straight from the bus (``receive="poll"``, lockstep
and deterministic) or from a python-can ``Notifier`` queue (``receive="notifier"``, real time).
While boot and the state machine wait for an answer they call the ``idle`` hook (the simulated
rig's ``exchange`` in lockstep) or sleep a little in real time. canopen supplies the object
dictionary (our EDS) used to encode SDO values.
"""

from __future__ import annotations

import collections
import math
import struct
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any, Literal

import can
from canopen.objectdictionary import ODVariable

from drivers import cia402
from drivers import od as o
from drivers.can_errors import BusEvent, BusState, decode_error_frame
from drivers.clock import Clock, MonotonicClock
from drivers.drive import (
    DriveError,
    DriveFeedback,
    DriveState,
    DriveUnreachableError,
    FaultEvent,
    FaultKind,
    HomingStatus,
    KnobDrives,
)
from drivers.sdo import SdoClient
from drivers.units import DriveConfig, MasterTimeouts, interpolation_period

_RPDO = struct.Struct(o.RPDO1_FORMAT)
_TPDO = struct.Struct(o.TPDO1_FORMAT)
_EMCY = struct.Struct("<HB5s")
MOTOR_SPEED_HEADROOM = 1.25
"""0x6080 = knob velocity limit x gear x this: room for the position loop's transients."""
_NMT_NAMES = {0x00: "boot-up", 0x04: "STOPPED", 0x05: "OPERATIONAL", 0x7F: "PRE-OPERATIONAL"}
_HOMING_DONE = cia402.SW_HOMING_ATTAINED | cia402.SW_TARGET_REACHED
MAX_PENDING_BUS_EVENTS = 256
"""Error frames can flood (a broken wire): older bus events are dropped and counted."""


class _Drive:
    """Master-side image of one drive (plain attributes: this is the hot path)."""

    def __init__(self, index: int, config: DriveConfig) -> None:
        self.index = index
        self.config = config
        self.node_id = config.node_id
        self.name = f"drive {index} (node {config.node_id})"
        self.cpd = config.counts_per_deg
        self.scale_A = config.current_scale_A
        self.min_counts = config.deg_to_counts(config.min_deg)
        self.max_counts = config.deg_to_counts(config.max_deg)
        self.controlword = 0
        self.target_counts = 0
        self.statusword = 0
        self.position_counts = 0
        self.current_raw = 0
        self.state = DriveState.UNKNOWN
        self.age_syncs = 0
        self.has_feedback = False
        self.stale_reported = False
        self.last_heartbeat_s: float | None = None
        self.nmt_state: int | None = None
        self.heartbeat_lost = False
        self.supervised = False
        self.last_emcy: int | None = None
        self.rebooted = False
        """Sent a boot-up while running: parameters lost, waits for fault_reset to re-configure."""
        self.homed = False
        self.sdo: SdoClient
        self.rpdo = can.Message(arbitration_id=0x200 + self.node_id, is_extended_id=False,
                                data=bytearray(_RPDO.size))
        self.feedback_key: tuple[int, int, int, DriveState, int] | None = None
        self.feedback: DriveFeedback | None = None
        """The last DriveFeedback built, reused while ``feedback_key`` is unchanged."""

    def snapshot(self) -> DriveFeedback:
        """Feedback as a DriveFeedback; one object per change, not per call (hot path)."""
        key = (self.position_counts, self.current_raw, self.statusword, self.state,
               self.age_syncs)
        fb = self.feedback
        if fb is None or key != self.feedback_key:
            fb = self.feedback = DriveFeedback(
                position_deg=self.position_counts / self.cpd,
                current_A=self.current_raw * self.scale_A, statusword=self.statusword,
                state=self.state, age_syncs=self.age_syncs)
            self.feedback_key = key
        return fb

    def pack_rpdo(self) -> can.Message:
        _RPDO.pack_into(self.rpdo.data, 0, self.controlword, self.target_counts)
        return self.rpdo


class CanOpenDrives(KnobDrives):
    """N CiA 402 drives on one python-can bus (``socketcan``/``can0`` or ``virtual``)."""

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
        self._drives = [_Drive(i, c) for i, c in enumerate(configs)]
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
        self._queue: collections.deque[can.Message] | None = None
        self._notifier: can.Notifier | None = None
        if receive == "notifier":
            self._queue = collections.deque()
            self._notifier = can.Notifier(bus, [_QueueListener(self._queue, self._on_bus_error)],
                                          timeout=0.05)
        elif receive != "poll":
            raise DriveError(f"receive must be 'poll' or 'notifier', not {receive!r}")
        self._lock = threading.Lock()

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

    # -- KnobDrives ------------------------------------------------------------------------
    @property
    def count(self) -> int:
        return len(self._drives)

    @property
    def configs(self) -> list[DriveConfig]:
        return [d.config for d in self._drives]

    def boot(self) -> None:
        self.pump()  # frames from before the reset (an earlier boot-up) must not count
        for d in self._drives:
            d.supervised = False
            d.has_feedback = False
            d.nmt_state = None
            d.rebooted = False
            d.homed = False
            self._send(0x000, bytes((0x81, d.node_id)))
        self._wait_until(lambda d: d.nmt_state is not None, self.timeouts.boot_s,
                         "boot-up message after NMT reset node")
        for d in self._drives:
            try:
                self._configure(d)
            except DriveError as exc:
                reason = str(exc).removeprefix(f"{d.name}: ")
                if reason.startswith("boot failed"):
                    raise
                self._boot_failed(d, reason)
        self._start_supervised(self._drives)

    def _start_supervised(self, drives: Sequence[_Drive]) -> None:
        """NMT start, wait for OPERATIONAL heartbeats, then supervise (heartbeat, TPDO age)."""
        for d in drives:
            d.nmt_state = None
            self._send(0x000, bytes((0x01, d.node_id)))
        self._wait_until(lambda d: d.nmt_state == 0x05, self.timeouts.boot_s,
                         "heartbeat in OPERATIONAL after NMT start", drives)
        now = self.clock.now_s()
        for d in drives:
            d.supervised = True
            d.heartbeat_lost = False
            d.last_heartbeat_s = now
            d.controlword = 0
            d.age_syncs = 0
            d.stale_reported = False
            d.rebooted = False

    def enable(self) -> None:
        self._walk({DriveState.OPERATION_ENABLED}, self._enable_command, "enable",
                   raise_on_timeout=True)

    def _enable_command(self, d: _Drive) -> int | None:
        if d.state is DriveState.FAULT:
            raise DriveError(f"{d.name}: cannot enable, drive is in FAULT "
                             f"({self._error_code_text(d)}); call fault_reset first")
        return cia402.next_command_to_enable(d.state, d.config.quick_stop_option,
                                             d.controlword & ~cia402.CW_HOMING_START)

    def disable(self) -> None:
        self._walk({DriveState.SWITCH_ON_DISABLED, DriveState.FAULT},
                   lambda d: cia402.CW_DISABLE_VOLTAGE, "disable", raise_on_timeout=True)

    def quick_stop(self) -> None:
        """Quick stop; never raises: a drive that does not answer becomes a STATE_TIMEOUT event."""
        self._walk({DriveState.QUICK_STOP_ACTIVE, DriveState.SWITCH_ON_DISABLED,
                    DriveState.FAULT}, lambda d: cia402.CW_QUICK_STOP, "quick stop",
                   raise_on_timeout=False)

    def halt(self, on: bool) -> None:
        for d in self._drives:
            d.controlword = (d.controlword | cia402.CW_HALT) if on else (
                d.controlword & ~cia402.CW_HALT)
            self._send_msg(d.pack_rpdo())

    def fault_reset(self) -> None:
        """Recover what can be: checks the bus is back, re-configures drives that rebooted
        (they come back SWITCH ON DISABLED, never moving), then resets drives in FAULT.

        Raises :class:`DriveUnreachableError` while the bus is off or a drive is silent.
        """
        if self.bus_state is BusState.BUS_OFF:
            raise DriveUnreachableError(
                "CAN bus-off: the interface has not restarted (give it restart-ms, see "
                "docs/drivers.md, or restart it by hand)")
        for d in self._drives:
            if d.heartbeat_lost and not d.rebooted:
                if d.age_syncs >= d.config.stale_after_syncs:
                    raise DriveUnreachableError(f"{d.name} silent: no heartbeat for "
                                                f"{self._silence_s(d):.3f} s and no TPDO for "
                                                f"{d.age_syncs} SYNCs")
                raise DriveUnreachableError(f"{d.name} sends no heartbeat for "
                                            f"{self._silence_s(d):.3f} s (its TPDOs arrive)")
        rebooted = [d for d in self._drives if d.rebooted]
        for d in rebooted:
            self._configure(d)
        if rebooted:
            self._start_supervised(rebooted)
        faulty = [d for d in self._drives if d.state is DriveState.FAULT]
        if not faulty:
            return
        for d in faulty:
            d.controlword = cia402.CW_DISABLE_VOLTAGE
        self._cycle()
        self._walk({DriveState.SWITCH_ON_DISABLED, DriveState.READY_TO_SWITCH_ON,
                    DriveState.SWITCHED_ON, DriveState.OPERATION_ENABLED},
                   lambda d: cia402.CW_FAULT_RESET, "fault reset", raise_on_timeout=True,
                   only=faulty)
        for d in faulty:
            d.controlword = cia402.CW_DISABLE_VOLTAGE
            d.last_emcy = None

    # -- homing (CiA 402 Homing Mode) ------------------------------------------------------
    def home(self, drives: Sequence[int] | None = None) -> list[HomingStatus]:
        """Run each chosen drive's configured homing method; ``none`` drives are skipped.

        Per drive: homing parameters and 0x6060 = 6 by SDO, enable, controlword bit 4 until the
        statusword says homing attained (or error, or ``homing.timeout_s``), then disable and
        back to CSP (0x6060 = 8). Leaves the drives disabled; raises :class:`DriveError` naming
        the drive, the method and the statusword when homing fails.
        """
        indices = range(self.count) if drives is None else drives
        chosen: list[_Drive] = []
        for i in indices:
            if isinstance(i, bool) or not isinstance(i, int) or not 0 <= i < self.count:
                raise DriveError(f"home: no drive {i!r} (drives 0..{self.count - 1})")
            chosen.append(self._drives[i])
        todo = [d for d in chosen if d.config.homing.enabled]
        for d in todo:
            if d.rebooted or not d.supervised:
                raise DriveUnreachableError(f"{d.name} is not running (rebooted or not booted);"
                                            f" reset it before homing")
            if d.state in (DriveState.FAULT, DriveState.FAULT_REACTION_ACTIVE):
                raise DriveError(f"{d.name}: cannot home, drive is in {d.state.value} "
                                 f"({self._emcy_text(d)}); call fault_reset first")
        if not todo:
            return self.homing_status()
        self._walk({DriveState.SWITCH_ON_DISABLED}, lambda d: cia402.CW_DISABLE_VOLTAGE,
                   "disable", raise_on_timeout=True, only=todo)
        for d in todo:
            d.homed = False
            self._write_homing_parameters(d)
        ok = False
        try:
            self._walk({DriveState.OPERATION_ENABLED}, self._enable_command, "enable",
                       raise_on_timeout=True, only=todo)
            for d in todo:
                mode = int(self.sdo_read(d.index, o.MODES_OF_OPERATION_DISPLAY))
                if mode != o.HOMING_MODE:
                    raise DriveError(f"{d.name}: homing ({d.config.homing.method_name}): the "
                                     f"drive reports mode {mode} (0x6061), not Homing Mode 6")
            self._search_home(todo)
            ok = True
        finally:
            self._leave_homing(todo, ok)
        return self.homing_status()

    def _write_homing_parameters(self, d: _Drive) -> None:
        h = d.config.homing
        cpd = d.cpd
        writes = [(o.HOMING_METHOD, 0, h.method),
                  (o.HOME_OFFSET, 0, round(h.home_offset_deg * cpd)),
                  (o.HOMING_SPEEDS, 1, round(h.switch_speed_deg_s * cpd)),
                  (o.HOMING_SPEEDS, 2, round(h.zero_speed_deg_s * cpd)),
                  (o.HOMING_ACCELERATION, 0, round(h.accel_deg_s2 * cpd))]
        if h.method in (-3, -4):
            writes.append((o.HOMING_CURRENT_THRESHOLD, 0, round(h.current_threshold_A * 1e3)))
        writes.append((o.MODES_OF_OPERATION, 0, o.HOMING_MODE))
        for index, subindex, value in writes:
            self.sdo_write(d.index, index, subindex, value)

    def _search_home(self, todo: Sequence[_Drive]) -> None:
        """Controlword bit 4 on; cycle until every drive reports homing attained."""
        for d in todo:
            d.controlword = cia402.CW_ENABLE_OPERATION | cia402.CW_HOMING_START
        start = self.clock.now_s()
        pending = list(todo)
        cycles = 0
        while pending:
            self._cycle()
            cycles += 1
            elapsed = self.clock.now_s() - start
            for d in list(pending):
                h = d.config.homing
                what = f"{d.name}: homing ({h.method_name}, method {h.method})"
                fresh = d.has_feedback and d.age_syncs == 0
                sw = d.statusword
                if fresh and cycles >= 2:  # the first answer may predate the start command
                    if d.state is not DriveState.OPERATION_ENABLED:
                        raise DriveError(f"{what} stopped: the drive is in {d.state.value} "
                                         f"(statusword 0x{sw:04X}, {self._emcy_text(d)})")
                    if sw & cia402.SW_HOMING_ERROR:
                        raise DriveError(f"{what} failed: the drive reports a homing error "
                                         f"(statusword 0x{sw:04X})")
                    if sw & _HOMING_DONE == _HOMING_DONE:
                        d.homed = True
                        pending.remove(d)
                        continue
                if elapsed > h.timeout_s:
                    self._event(FaultKind.STATE_TIMEOUT, d.index,
                                f"{what} timed out after {h.timeout_s} s")
                    raise DriveError(f"{what} timed out after {h.timeout_s} s (statusword "
                                     f"0x{sw:04X}, feedback {d.age_syncs} SYNCs old)")

    def _leave_homing(self, todo: Sequence[_Drive], ok: bool) -> None:
        """Stop (quick stop on failure), disable, back to CSP. Never masks the first error."""
        try:
            if not ok:
                self._walk({DriveState.QUICK_STOP_ACTIVE, DriveState.SWITCH_ON_DISABLED,
                            DriveState.FAULT}, lambda d: cia402.CW_QUICK_STOP, "quick stop",
                           raise_on_timeout=False, only=todo)
            self._walk({DriveState.SWITCH_ON_DISABLED, DriveState.FAULT},
                       lambda d: cia402.CW_DISABLE_VOLTAGE, "disable", raise_on_timeout=ok,
                       only=todo)
            for d in todo:
                self.sdo_write(d.index, o.MODES_OF_OPERATION, 0, o.CSP_MODE)
                d.target_counts = d.position_counts
        except DriveError:
            if ok:
                raise

    def homing_status(self) -> list[HomingStatus]:
        return [HomingStatus(d.config.homing.method_name, d.config.homing.required, d.homed,
                             d.config.homing.home_offset_deg) for d in self._drives]

    def write_targets(self, knob_deg: Sequence[float]) -> None:
        drives = self._drives
        if len(knob_deg) != len(drives):
            raise DriveError(f"write_targets needs {len(drives)} knob angles, "
                             f"got {len(knob_deg)}")
        for d, deg in zip(drives, knob_deg, strict=True):
            counts = deg * d.cpd
            if not math.isfinite(counts):
                raise DriveError(f"{d.name}: target {deg!r} deg is not a finite number")
            c = round(counts)
            d.target_counts = d.min_counts if c < d.min_counts else (
                d.max_counts if c > d.max_counts else c)
            self._send_msg(d.pack_rpdo())

    def sync(self) -> None:
        self._heartbeat_if_due()
        self._send_msg(self._sync_msg)
        self.syncs_sent += 1
        for d in self._drives:
            d.age_syncs += 1

    def pump(self) -> None:
        handle = self._on_message
        queue = self._queue
        try:
            if queue is None:
                recv = self.bus.recv
                while (msg := recv(0)) is not None:
                    handle(msg)
            else:
                popleft = queue.popleft
                while queue:
                    self._recv_failing = False
                    handle(popleft())
        except can.CanError as exc:
            self._event(FaultKind.BUS_ERROR, -1, f"CAN receive failed: {exc}")
        self._supervise()

    def feedback(self) -> list[DriveFeedback]:
        return [d.snapshot() for d in self._drives]

    def heartbeat_lost(self) -> list[bool]:
        with self._lock:
            return [d.heartbeat_lost for d in self._drives]

    def poll_events(self) -> list[FaultEvent]:
        with self._lock:
            events, self._events = self._events, []
        return events

    def close(self) -> None:
        if self._notifier is not None:
            self._notifier.stop()
            self._notifier = None
        if self._own_bus:
            self.bus.shutdown()

    # -- SDO client (expedited + segmented upload) ----------------------------------------
    def sdo_read(self, drive: int, index: int, subindex: int = 0) -> Any:
        """Read one object by SDO, decoded with our EDS's data type."""
        d = self._drives[drive]
        var = self._variable(d, index, subindex)
        return var.decode_raw(self.sdo_upload(drive, index, subindex))

    def sdo_write(self, drive: int, index: int, subindex: int, value: int) -> None:
        """Write one object by SDO, encoded with our EDS's data type."""
        d = self._drives[drive]
        var = self._variable(d, index, subindex)
        try:
            data = var.encode_raw(value)
        except (struct.error, ValueError, TypeError) as exc:
            raise DriveError(f"{d.name}: value {value!r} does not fit 0x{index:04X}:"
                             f"{subindex:02X} ({var.name}): {exc}") from exc
        self.sdo_download(drive, index, subindex, data)

    def sdo_upload(self, drive: int, index: int, subindex: int = 0) -> bytes:
        """Raw SDO upload (expedited or segmented); raises DriveError on abort or timeout."""
        return self._drives[drive].sdo.upload(index, subindex)

    def sdo_download(self, drive: int, index: int, subindex: int, data: bytes) -> None:
        """Raw expedited SDO download of 1..4 bytes; raises DriveError on abort or timeout."""
        self._drives[drive].sdo.download(index, subindex, data)

    def _variable(self, d: _Drive, index: int, subindex: int) -> ODVariable:
        try:
            obj = self._od[index]
            return obj if isinstance(obj, ODVariable) else obj[subindex]
        except KeyError:
            raise DriveError(f"{d.name}: object 0x{index:04X}:{subindex:02X} is not in our "
                             f"EDS ({o.EDS_PATH.name})") from None

    # -- boot configuration ----------------------------------------------------------------
    def _configure(self, d: _Drive) -> None:
        c = d.config
        i = d.index
        device_type = int(self.sdo_read(i, o.DEVICE_TYPE))
        if device_type & 0xFFFF != o.DEVICE_PROFILE_402:
            self._boot_failed(d, f"device type 0x{device_type:08X} is not a CiA 402 drive")
        vendor = int(self.sdo_read(i, o.IDENTITY, 1))
        product = int(self.sdo_read(i, o.IDENTITY, 2))
        if (c.vendor_id and vendor != c.vendor_id) or (c.product_code and
                                                        product != c.product_code):
            self._boot_failed(d, f"identity 0x1018 is vendor 0x{vendor:08X} product "
                                 f"0x{product:08X}, config expects vendor 0x{c.vendor_id:08X} "
                                 f"product 0x{c.product_code:08X}")
        rated_mA = int(self.sdo_read(i, o.MOTOR_RATED_CURRENT))
        if abs(rated_mA - c.rated_current_mA) > 0.01 * c.rated_current_mA:
            self._boot_failed(d, f"motor rated current 0x6075 is {rated_mA} mA but "
                                 f"current_scale_A={c.current_scale_A} implies "
                                 f"{c.rated_current_mA} mA")
        n = d.node_id
        value, exponent = self.interpolation
        cpd = d.cpd
        writes: list[tuple[int, int, int]] = [
            (o.RPDO1_COMM, 1, 0x80000000 | (0x200 + n)),
            (o.RPDO1_COMM, 2, 1),
            (o.RPDO1_MAP, 0, 0),
            *[(o.RPDO1_MAP, k + 1, o.mapping_entry(*m)) for k, m in enumerate(o.RPDO1_MAPPING)],
            (o.RPDO1_MAP, 0, len(o.RPDO1_MAPPING)),
            (o.RPDO1_COMM, 1, 0x200 + n),
            (o.RPDO2_COMM, 1, 0x80000000 | (0x300 + n)),
            (o.TPDO1_COMM, 1, 0x80000000 | (0x180 + n)),
            (o.TPDO1_COMM, 2, 1),
            (o.TPDO1_MAP, 0, 0),
            *[(o.TPDO1_MAP, k + 1, o.mapping_entry(*m)) for k, m in enumerate(o.TPDO1_MAPPING)],
            (o.TPDO1_MAP, 0, len(o.TPDO1_MAPPING)),
            (o.TPDO1_COMM, 1, 0x180 + n),
            (o.TPDO2_COMM, 1, 0x80000000 | (0x280 + n)),
            (o.CYCLE_PERIOD, 0, round(self.period_s * 1e6)),
            (o.INTERPOLATION_PERIOD, 1, value),
            (o.INTERPOLATION_PERIOD, 2, exponent),
            (o.MODES_OF_OPERATION, 0, o.CSP_MODE),
            (o.SOFTWARE_POSITION_LIMIT, 1, d.min_counts),
            (o.SOFTWARE_POSITION_LIMIT, 2, d.max_counts),
            (o.MAX_PROFILE_VELOCITY, 0, round(c.max_velocity_deg_s * cpd)),
            (o.MAX_MOTOR_SPEED, 0, round(c.max_velocity_deg_s * c.gear_ratio / 6.0
                                         * MOTOR_SPEED_HEADROOM)),
            (o.QUICK_STOP_DECELERATION, 0, round(c.max_accel_deg_s2 * cpd)),
            (o.FOLLOWING_ERROR_WINDOW, 0, round(c.following_error_deg * cpd)),
            (o.FOLLOWING_ERROR_TIMEOUT, 0, c.following_error_timeout_ms),
            (o.QUICK_STOP_OPTION, 0, c.quick_stop_option),
            (o.ABORT_CONNECTION_OPTION, 0, c.abort_connection_option),
            (o.PRODUCER_HEARTBEAT, 0, c.heartbeat_producer_ms),
            (o.CONSUMER_HEARTBEAT, 1, (self.master_node_id << 16) | c.master_heartbeat_timeout_ms),
        ]
        for index, subindex, val in writes:
            self.sdo_write(i, index, subindex, val)

    def _boot_failed(self, d: _Drive, reason: str) -> None:
        self._event(FaultKind.BOOT_FAILED, d.index, f"{d.name}: {reason}")
        raise DriveError(f"{d.name}: boot failed: {reason}")

    # -- state machine ---------------------------------------------------------------------
    def _walk(self, goal: set[DriveState], command: Callable[[_Drive], int | None], what: str,
              raise_on_timeout: bool, only: Sequence[_Drive] | None = None) -> None:
        """Cycle (RPDO, SYNC, answer) until every drive is in a goal state, or time out."""
        drives = list(only) if only is not None else self._drives
        start = self.clock.now_s()
        while True:
            pending = []
            for d in drives:
                fresh = d.has_feedback and d.age_syncs == 0
                if fresh and d.state in goal:
                    continue
                pending.append(d)
                if not fresh:
                    continue
                cw = command(d)
                if cw is None:
                    raise DriveError(f"{d.name}: cannot {what} from state {d.state.value} "
                                     f"(statusword 0x{d.statusword:04X})")
                if d.state is not DriveState.OPERATION_ENABLED:
                    d.target_counts = d.position_counts
                d.controlword = cw | (d.controlword & cia402.CW_HALT)
            if not pending:
                return
            timeout_s = self.timeouts.transition_s(what)
            if self.clock.now_s() - start > timeout_s:
                silent = [d for d in pending if self._silent_since(d, start)]
                for d in pending:
                    reason = (f"{d.name}: {what} timed out after {timeout_s} s in "
                              f"state {d.state.value} (statusword 0x{d.statusword:04X}, "
                              f"feedback {d.age_syncs} SYNCs old)")
                    if d in silent:
                        reason = (f"{d.name} silent: no TPDO and no heartbeat for "
                                  f"{self._silence_s(d):.3f} s ({what} not possible)")
                    self._event(FaultKind.STATE_TIMEOUT, d.index, reason)
                if raise_on_timeout:
                    if silent:
                        raise DriveUnreachableError(
                            f"{silent[0].name} silent: no TPDO and no heartbeat for "
                            f"{self._silence_s(silent[0]):.3f} s ({what} not possible)")
                    raise DriveError(reason)
                return
            self._cycle()

    def _cycle(self) -> None:
        """One tick with the current controlwords and targets (used while walking states).

        Lockstep: one idle call is one period. Real time: wait for the answers, at most a period.
        """
        for d in self._drives:
            self._send_msg(d.pack_rpdo())
        self.sync()
        if self.idle is not None:
            self._wait()
            return
        end = self.clock.now_s() + self.period_s
        while True:
            self._wait()
            if self.clock.now_s() >= end:
                return
            if all(d.age_syncs == 0 for d in self._drives):
                remaining = end - self.clock.now_s()
                if remaining > 0:
                    time.sleep(remaining)
                return

    def _wait(self) -> None:
        """Let the other side answer: the lockstep idle hook, else a short sleep."""
        if self.idle is not None:
            self.idle()
        else:
            time.sleep(min(self.period_s, 0.001))
        self._heartbeat_if_due()
        self.pump()

    def _heartbeat_if_due(self) -> None:
        """Master heartbeat (what the drives' 0x1016 consumers watch), at its period on average."""
        now = self.clock.now_s()
        nxt = self._next_heartbeat_s
        if nxt is None or now >= nxt - 1e-9:
            period = self.master_heartbeat_s
            nxt = now + period if nxt is None else nxt + period
            self._next_heartbeat_s = nxt if nxt > now else now + period
            self._send_msg(self._hb_msg)

    def _silent_since(self, d: _Drive, start_s: float) -> bool:
        """No TPDO answered a SYNC and no heartbeat arrived since ``start_s``."""
        last_hb = d.last_heartbeat_s
        return (not d.has_feedback or d.age_syncs > 0) and (last_hb is None or last_hb < start_s)

    def _silence_s(self, d: _Drive) -> float:
        last = d.last_heartbeat_s
        return self.clock.now_s() - last if last is not None else math.inf

    def _wait_until(self, done: Callable[[_Drive], bool], timeout_s: float, what: str,
                    drives: Sequence[_Drive] | None = None) -> None:
        drives = self._drives if drives is None else drives
        deadline = self.clock.now_s() + timeout_s
        while not all(done(d) for d in drives):
            if self.clock.now_s() > deadline:
                missing = [d for d in drives if not done(d)]
                for d in missing:
                    self._event(FaultKind.BOOT_FAILED, d.index,
                                f"{d.name}: no {what} within {timeout_s} s")
                raise DriveError(f"{missing[0].name}: boot failed: no {what} within "
                                 f"{timeout_s} s")
            self._wait()

    # -- receive path ----------------------------------------------------------------------
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

    def _tpdo_handler(self, d: _Drive) -> Callable[[bytearray], None]:
        unpack = _TPDO.unpack
        size = _TPDO.size
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

    def _heartbeat_handler(self, d: _Drive) -> Callable[[bytearray], None]:
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

    def _emcy_handler(self, d: _Drive) -> Callable[[bytearray], None]:
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

    def _on_reboot(self, d: _Drive) -> None:
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

    # -- send path -------------------------------------------------------------------------
    def _send(self, can_id: int, data: bytes) -> None:
        self._send_msg(can.Message(arbitration_id=can_id, is_extended_id=False, data=data))

    def _send_msg(self, msg: can.Message) -> None:
        try:
            self.bus.send(msg)
        except can.CanError as exc:
            if not self._send_failing:
                self._send_failing = True
                self._event(FaultKind.BUS_ERROR, -1,
                            f"CAN send of 0x{msg.arbitration_id:03X} failed: {exc}")
            return
        self._send_failing = False
        self.frames_sent += 1

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

    def _error_code_text(self, d: _Drive) -> str:
        """0x603F read from the drive (falls back to the last EMCY if the read fails)."""
        try:
            code = int(self.sdo_read(d.index, o.ERROR_CODE))
        except DriveError:
            return self._emcy_text(d)
        return f"0x603F error code 0x{code:04X} {o.emcy_meaning(code)}"

    @staticmethod
    def _emcy_text(d: _Drive) -> str:
        if d.last_emcy is None:
            return "no EMCY received"
        return f"EMCY 0x{d.last_emcy:04X} {o.emcy_meaning(d.last_emcy)}"


class _QueueListener(can.Listener):
    """Notifier thread -> deque; errors of the receive thread become BUS_ERROR events."""

    def __init__(self, queue: collections.deque[can.Message],
                 on_error: Callable[[Exception], None]) -> None:
        self._queue = queue
        self._on_error = on_error

    def on_message_received(self, msg: can.Message) -> None:
        self._queue.append(msg)

    def on_error(self, exc: Exception) -> None:
        self._on_error(exc)
