"""The cyclic exchange and the SDO access of the CANopen master.

Per tick: one RPDO per drive (:meth:`MasterExchange.write_targets`), the master heartbeat when
due and SYNC (:meth:`MasterExchange.sync`), then the answers (:meth:`MasterExchange.pump`).
While boot and the state machine wait, :meth:`MasterExchange._wait` calls the ``idle`` hook (the
simulated rig's ``exchange`` in lockstep) or sleeps a little in real time.
"""

from __future__ import annotations

import math
import struct
import time
from collections.abc import Sequence
from typing import Any

import can
from canopen.objectdictionary import ODVariable

from drivers import od as o
from drivers.drive import DriveError, DriveFeedback, FaultKind
from drivers.drive_image import DriveImage
from drivers.master_supervision import MasterSupervision
from drivers.units import DriveConfig


class MasterExchange(MasterSupervision):
    """Send path, cyclic PDO exchange and SDO access of :class:`CanOpenDrives`."""

    @property
    def count(self) -> int:
        return len(self._drives)

    @property
    def configs(self) -> list[DriveConfig]:
        return [d.config for d in self._drives]

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

    def _variable(self, d: DriveImage, index: int, subindex: int) -> ODVariable:
        try:
            obj = self._od[index]
            return obj if isinstance(obj, ODVariable) else obj[subindex]
        except KeyError:
            raise DriveError(f"{d.name}: object 0x{index:04X}:{subindex:02X} is not in our "
                             f"EDS ({o.EDS_PATH.name})") from None
