"""The CiA 402 power state machine as the master walks it: enable, disable, quick stop, halt,
fault reset (docs/drivers.md, "CiA 402 state machine")."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from drivers import cia402
from drivers import od as o
from drivers.can_errors import BusState
from drivers.drive import DriveError, DriveState, DriveUnreachableError, FaultKind
from drivers.drive_image import DriveImage
from drivers.master_boot import MasterBoot


class MasterStates(MasterBoot):
    """State transitions of the drives of :class:`CanOpenDrives`, by RPDO + SYNC cycles."""

    def enable(self) -> None:
        self._walk({DriveState.OPERATION_ENABLED}, self._enable_command, "enable",
                   raise_on_timeout=True)

    def _enable_command(self, d: DriveImage) -> int | None:
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

    def _walk(self, goal: set[DriveState], command: Callable[[DriveImage], int | None], what: str,
              raise_on_timeout: bool, only: Sequence[DriveImage] | None = None) -> None:
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

    def _error_code_text(self, d: DriveImage) -> str:
        """0x603F read from the drive (falls back to the last EMCY if the read fails)."""
        try:
            code = int(self.sdo_read(d.index, o.ERROR_CODE))
        except DriveError:
            return self._emcy_text(d)
        return f"0x603F error code 0x{code:04X} {o.emcy_meaning(code)}"
