"""A simulated CiA 402 drive as a CANopen slave: what canopen's ``LocalNode`` leaves out.

It owns its object values (typed by our EDS), serves SDO through canopen's ``SdoServer``, and adds
what a real drive does on the bus: NMT, boot-up and heartbeat producer, heartbeat consumer with the
0x6007 reaction, SYNC-latched RPDOs, SYNC-triggered TPDOs, EMCY, the power state machine with fault
and quick stop (:mod:`simrig.drive_power`), and Cyclic Synchronous Position tracking
through :class:`Motor`.

The node never reads a clock or a bus itself: the rig hands it frames and the time, so a lockstep
run is a pure function of its inputs.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from canopen.sdo import SdoServer

from drivers import od as o
from drivers.drive import DriveState
from simrig.drive_homing import SimHoming
from simrig.drive_od import DriveObjectStore
from simrig.drive_power import PowerStateMachine
from simrig.motor import Motor

SendFn = Callable[[int, bytes], None]

NMT_INITIALISING = 0x00
NMT_STOPPED = 0x04
NMT_OPERATIONAL = 0x05
NMT_PRE_OPERATIONAL = 0x7F

# States read by both drives every period, as module constants (a global read, not an enum
# class lookup; simrig.drive_power keeps its own for the same reason).
_OPERATION_ENABLED = DriveState.OPERATION_ENABLED
_FAULT_REACTION_ACTIVE = DriveState.FAULT_REACTION_ACTIVE
_QUICK_STOP_ACTIVE = DriveState.QUICK_STOP_ACTIVE


class _ServerLink:
    """What canopen's SdoServer needs from a network: a way to send its response."""

    def __init__(self, send: SendFn) -> None:
        self._send = send

    def send_message(self, can_id: int, data: bytes, remote: bool = False) -> None:
        self._send(can_id, bytes(data))


class SimDriveNode(PowerStateMachine, DriveObjectStore):
    """One simulated knob drive (CiA 301 slave + CiA 402 device, CSP only)."""

    def __init__(self, node_id: int, motor: Motor, counts_per_deg: float, send: SendFn,
                 *, vendor_id: int = 0, product_code: int = 0x402,
                 rated_current_mA: int = 2000) -> None:
        self.node_id = node_id
        self.motor = motor
        self.counts_per_deg = counts_per_deg
        self._send = send
        self.od = o.load_od(node_id)
        self.object_dictionary = self.od
        self._defaults: dict[tuple[int, int], Any] = {}
        self._defaults[(o.IDENTITY, 1)] = vendor_id
        self._defaults[(o.IDENTITY, 2)] = product_code
        self._defaults[(o.MOTOR_RATED_CURRENT, 0)] = rated_current_mA
        self.sdo = SdoServer(0x600 + node_id, 0x580 + node_id, self)
        self.sdo.network = _ServerLink(send)  # type: ignore[assignment]
        self.encoder_zero_deg = 0.0
        """Motor position (knob degrees) the relative encoder reads as 0: where it powered up,
        until homing moves it."""
        self.index_phase_deg = 0.0
        """Where the encoder's index pulses are (one per motor revolution from here)."""
        self.homing = SimHoming(self)
        # fault injection
        self.silent = False
        self.heartbeat_stopped = False
        self.corrupt_next_tpdo = False
        self.nmt_state = NMT_INITIALISING
        self.reset(0.0)

    # -- NMT ------------------------------------------------------------------------------
    def reset(self, now_s: float) -> None:
        """Power-on / NMT reset node: defaults back, state machine to SWITCH ON DISABLED."""
        self.values: dict[tuple[int, int], Any] = {}
        self.controlword = 0
        self.target_counts = 0
        self.mode = 0
        self.mode_display = 0
        self.error_code = 0
        self.error_register = 0
        self.state = DriveState.SWITCH_ON_DISABLED
        self.powered = False
        self.halted = False
        self.internal_limit = False
        self.following_error = False
        self.velocity_counts_s = 0
        self.following_error_counts = 0
        self.current_raw = 0
        self.statusword = 0
        self._sw_key: tuple[DriveState, bool, bool, bool, bool] | None = None
        self._sw_base = 0
        """The last statusword key and its statusword before the homing bits."""
        self._fe_since_s: float | None = None
        self._sync_count = 0
        self._rpdo_pending: bytes | bytearray | None = None
        self._master_hb_s: float | None = None
        self._master_lost = False
        self._internal_target_deg = self.motor.position_deg
        self._qs_velocity_deg_s = 0.0
        self.homing.clear()
        self.position_counts = round((self.motor.position_deg - self.encoder_zero_deg)
                                     * self.counts_per_deg)
        self._configure_pdos()
        self._update_statusword()
        self.nmt_state = NMT_PRE_OPERATIONAL
        self._next_heartbeat_s = now_s
        self._emit(0x700 + self.node_id, b"\x00")  # boot-up

    def reboot(self, now_s: float) -> None:
        """Power cycle: the relative encoder restarts at 0 where the motor is, PDO mapping and
        every parameter are back to their defaults, and the boot-up message goes out."""
        self.encoder_zero_deg = self.motor.position_deg
        self.reset(now_s)

    def _nmt_command(self, data: bytes | bytearray, now_s: float) -> None:
        if len(data) != 2 or data[1] not in (0, self.node_id):
            return
        cs = data[0]
        if cs == 0x01:
            self._configure_pdos()
            self.nmt_state = NMT_OPERATIONAL
        elif cs == 0x02:
            self.nmt_state = NMT_STOPPED
        elif cs == 0x80:
            self.nmt_state = NMT_PRE_OPERATIONAL
        elif cs in (0x81, 0x82):
            self.reset(now_s)

    # -- frames ---------------------------------------------------------------------------
    def on_frame(self, can_id: int, data: bytes | bytearray, now_s: float) -> None:
        """Handle one received frame (SYNC is handled by :meth:`on_sync`)."""
        if can_id == self._rpdo_cob:
            if self.nmt_state == NMT_OPERATIONAL:
                if len(data) != self._rpdo_len:
                    self.emcy(0x8210, fault=False)
                elif self._rpdo_sync:
                    self._rpdo_pending = data
                else:
                    self._apply_rpdo(data, now_s)
        elif can_id == 0x600 + self.node_id:
            if self.nmt_state != NMT_STOPPED and not self.silent:
                self.sdo.on_request(can_id, data, now_s)
        elif can_id == 0:
            self._nmt_command(data, now_s)
        elif can_id == self._master_hb_cob:
            self._master_hb_s = now_s
            self._master_lost = False

    def on_sync(self, now_s: float) -> None:
        """SYNC: latch the buffered RPDO (applied before the motion of this period)."""
        if self.nmt_state != NMT_OPERATIONAL:
            return
        self._sync_count += 1
        if self._rpdo_pending is not None:
            self._apply_rpdo(self._rpdo_pending, now_s)
            self._rpdo_pending = None

    def _apply_rpdo(self, data: bytes | bytearray, now_s: float) -> None:
        if self._rpdo_csp:  # the mapping the master writes: controlword, target position
            cw, target = self._rpdo_struct.unpack(data)
            self.write_controlword(cw)
            self.target_counts = target
            return
        for attr, value in zip(self._rpdo_attrs, self._rpdo_struct.unpack(data), strict=True):
            if attr == "controlword":
                self.write_controlword(value)
            elif attr == "mode":
                self.mode = value
            else:
                setattr(self, attr, value)

    # -- used by the homing mode ----------------------------------------------------------
    @property
    def internal_target_deg(self) -> float:
        return self._internal_target_deg

    def hold_position(self) -> None:
        """Stop where the motor is (end or interruption of a homing search, mode change)."""
        self._internal_target_deg = self.motor.position_deg
        self.target_counts = round((self.motor.position_deg - self.encoder_zero_deg)
                                   * self.counts_per_deg)

    def value(self, index: int, subindex: int) -> Any:
        """An object's value as the drive uses it (written, else its default)."""
        return self._value(index, subindex)

    # -- one period of motion -------------------------------------------------------------
    def motion_target_deg(self) -> float:
        """Where the motor goes this period (called after SYNC, before the physics step)."""
        dt = self.motor.dt_s
        if self.state is _OPERATION_ENABLED and not self.halted:
            if self.mode_display == o.HOMING_MODE:
                self._internal_target_deg = self.homing.target_deg(dt)
                return self._internal_target_deg
            target = self.target_counts
            lo = self._limit_lo
            hi = self._limit_hi
            limited = target < lo or target > hi
            if limited:
                target = lo if target < lo else hi
            target_deg = target / self.counts_per_deg + self.encoder_zero_deg
            vmax = self._vmax_deg_s
            step = target_deg - self._internal_target_deg
            if step > vmax * dt or step < -vmax * dt:
                target_deg = self._internal_target_deg + (vmax * dt if step > 0 else -vmax * dt)
                limited = True
            self.internal_limit = limited
            self._internal_target_deg = target_deg
            return target_deg
        if self.powered:  # quick stop, halt, fault reaction: ramp to standstill
            decel = self._qs_decel_deg_s2
            v = self._qs_velocity_deg_s
            dv = decel * dt
            v = 0.0 if abs(v) <= dv else v - dv if v > 0 else v + dv
            self._qs_velocity_deg_s = v
            self._internal_target_deg += v * dt
            return self._internal_target_deg
        return self.motor.position_deg

    def end_of_period(self, knob_torque_Nm: float, measured_current_A: float, now_s: float
                      ) -> None:
        """After the physics step: actual values, following error, state timers, heartbeat."""
        motor = self.motor
        cpd = self.counts_per_deg
        self.position_counts = round((motor.position_deg - self.encoder_zero_deg) * cpd)
        self.velocity_counts_s = round(motor.velocity_deg_s * cpd)
        raw = round(measured_current_A * self._raw_per_A) if self.powered else 0
        self.current_raw = -32768 if raw < -32768 else 32767 if raw > 32767 else raw
        state = self.state
        if state is _OPERATION_ENABLED and not self.halted:
            err = round((self._internal_target_deg - motor.position_deg) * cpd)
            self.following_error_counts = err
            window = self._fe_window
            if abs(err) > window:
                if self._fe_since_s is None:
                    self._fe_since_s = now_s
                elif now_s - self._fe_since_s >= self._fe_timeout_s:
                    self.following_error = True
                    self.fault(0x8611)
            else:
                self._fe_since_s = None
        else:
            self._fe_since_s = None
        if state is _OPERATION_ENABLED and self.homing.active:
            self.homing.after_step(measured_current_A)
            self.position_counts = round((motor.position_deg - self.encoder_zero_deg) * cpd)
        if state is _FAULT_REACTION_ACTIVE and self._qs_velocity_deg_s == 0.0:
            self._set_state(DriveState.FAULT)
        elif state is _QUICK_STOP_ACTIVE and self._qs_velocity_deg_s == 0.0 and (
                self._value(o.QUICK_STOP_OPTION, 0) in (1, 2)):
            self._set_state(DriveState.SWITCH_ON_DISABLED)
        self._supervise_master(now_s)
        self._update_statusword()

    def _supervise_master(self, now_s: float) -> None:
        timeout_s = self._master_timeout_s
        if not timeout_s or self._master_hb_s is None or self._master_lost:
            return
        if now_s - self._master_hb_s > timeout_s:
            self._master_lost = True
            self.emcy(0x8130, fault=False)
            self.error_register |= 0x10
            if self.state is DriveState.OPERATION_ENABLED:
                action = self._value(o.ABORT_CONNECTION_OPTION, 0)
                if action == 1:
                    self.fault(0x8130)
                elif action == 2:
                    self._set_state(DriveState.SWITCH_ON_DISABLED)
                elif action == 3:
                    self._start_quick_stop()

    def transmit(self, sync_seen: bool, now_s: float) -> None:
        """Send the TPDO due on this SYNC and the heartbeat when due."""
        if sync_seen and self.nmt_state == NMT_OPERATIONAL and self._tpdo_cob is not None:
            every = self._tpdo_every
            if every and self._sync_count % every == 0:
                data = self._tpdo_struct.pack(*self._tpdo_values(self))
                if self.corrupt_next_tpdo:
                    self.corrupt_next_tpdo = False
                    data = data[:-3]
                self._emit(self._tpdo_cob, data)
        period_ms = self._hb_period_ms
        if period_ms and now_s >= self._next_heartbeat_s - 1e-9:
            # keep the period on average even when ticks do not divide it
            period_s = period_ms * 1e-3
            nxt = self._next_heartbeat_s + period_s
            self._next_heartbeat_s = nxt if nxt > now_s else now_s + period_s
            if not self.heartbeat_stopped:
                self._emit(0x700 + self.node_id, bytes((self.nmt_state,)))
        elif not period_ms:
            self._next_heartbeat_s = now_s

    def _emit(self, can_id: int, data: bytes) -> None:
        if not self.silent:
            self._send(can_id, data)
