"""CiA 402 Homing Mode driven by the master: parameters by SDO, the search by controlword bit 4,
then back to Cyclic Synchronous Position (docs/drivers.md, "Homing")."""

from __future__ import annotations

from collections.abc import Sequence

from drivers import cia402
from drivers import od as o
from drivers.drive import DriveError, DriveState, DriveUnreachableError, FaultKind, HomingStatus
from drivers.drive_image import DriveImage
from drivers.master_states import MasterStates

_HOMING_DONE = cia402.SW_HOMING_ATTAINED | cia402.SW_TARGET_REACHED


class MasterHoming(MasterStates):
    """Homing of the drives of :class:`CanOpenDrives`."""

    def home(self, drives: Sequence[int] | None = None) -> list[HomingStatus]:
        """Run each chosen drive's configured homing method; ``none`` drives are skipped.

        Per drive: homing parameters and 0x6060 = 6 by SDO, enable, controlword bit 4 until the
        statusword says homing attained (or error, or ``homing.timeout_s``), then disable and
        back to CSP (0x6060 = 8). Leaves the drives disabled; raises :class:`DriveError` naming
        the drive, the method and the statusword when homing fails.
        """
        indices = range(self.count) if drives is None else drives
        chosen: list[DriveImage] = []
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

    def _write_homing_parameters(self, d: DriveImage) -> None:
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

    def _search_home(self, todo: Sequence[DriveImage]) -> None:
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

    def _leave_homing(self, todo: Sequence[DriveImage], ok: bool) -> None:
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
