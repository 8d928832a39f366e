"""The simulated drive's CiA 402 power state machine: controlword in, state and statusword out.

A mix-in of :class:`simrig.drive_node.SimDriveNode` (split from it): the transitions a
controlword makes, quick stop and fault reactions, EMCY frames, and the statusword cached per
(state, flags). The node owns the attributes declared below.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

from drivers import cia402
from drivers import od as o
from drivers.drive import DriveState
from simrig.drive_homing import HOMING_BITS
from simrig.motor import Motor

_QS_HOLD_OPTIONS = (5, 6, 7, 8)
# The states a period checks, as module constants: an enum member read through its class costs
# several times a global read on Python 3.11, and these are read by both drives every tick.
_OPERATION_ENABLED = DriveState.OPERATION_ENABLED
_FAULT_REACTION_ACTIVE = DriveState.FAULT_REACTION_ACTIVE
_QUICK_STOP_ACTIVE = DriveState.QUICK_STOP_ACTIVE
_POWERED = frozenset((DriveState.OPERATION_ENABLED, DriveState.QUICK_STOP_ACTIVE,
                      DriveState.FAULT_REACTION_ACTIVE))


def _statusword(state: DriveState, halted: bool, internal_limit: bool, following_error: bool,
                error: bool) -> int:
    """Statusword for a state and the flag bits (CiA 402 bit definitions)."""
    sw = cia402.STATE_BITS[state] | cia402.SW_REMOTE
    if state not in (DriveState.SWITCH_ON_DISABLED, DriveState.NOT_READY_TO_SWITCH_ON,
                     DriveState.FAULT) or state in _POWERED:
        sw |= cia402.SW_VOLTAGE_ENABLED
    if state not in (DriveState.QUICK_STOP_ACTIVE, DriveState.SWITCH_ON_DISABLED,
                     DriveState.FAULT, DriveState.FAULT_REACTION_ACTIVE,
                     DriveState.NOT_READY_TO_SWITCH_ON):
        sw |= cia402.SW_QUICK_STOP
    if state is DriveState.OPERATION_ENABLED and not halted:
        sw |= cia402.SW_FOLLOWS_TARGET
    if internal_limit:
        sw |= cia402.SW_INTERNAL_LIMIT
    if following_error:
        sw |= cia402.SW_FOLLOWING_ERROR
    if error and state is not DriveState.FAULT:
        sw |= cia402.SW_WARNING
    return sw


_STATUSWORDS: dict[tuple[DriveState, bool, bool, bool, bool], int] = {}


class PowerStateMachine:
    """The power state machine of one simulated drive (the node supplies the state)."""

    motor: Motor
    homing: Any
    controlword: int
    state: DriveState
    powered: bool
    halted: bool
    internal_limit: bool
    following_error: bool
    error_code: int
    error_register: int
    mode: int
    mode_display: int
    statusword: int
    target_counts: int
    position_counts: int
    velocity_counts_s: int
    _sw_key: tuple[DriveState, bool, bool, bool, bool] | None
    _sw_base: int
    _internal_target_deg: float
    _qs_velocity_deg_s: float

    node_id: int
    _value: Callable[[int, int], Any]  # the object store's
    _emit: Callable[[int, bytes], None]  # the node's (silent drives send nothing)

    # -- CiA 402 power state machine ------------------------------------------------------
    def write_controlword(self, cw: int) -> None:
        """Apply a controlword (level-triggered, except fault reset and QUICK STOP -> ENABLED,
        which need a change of the controlword)."""
        previous = self.controlword
        if cw == previous and self.state is _OPERATION_ENABLED:
            return
        rising_reset = bool(cw & 0x80) and not self.controlword & 0x80
        self.controlword = cw
        halted = bool(cw & cia402.CW_HALT)
        if halted and not self.halted:
            self._qs_velocity_deg_s = self.motor.velocity_deg_s
        self.halted = halted
        s = self.state
        S = DriveState
        if s is S.FAULT:
            if rising_reset:
                self.error_code = 0
                self.error_register = 0
                self.following_error = False
                self._set_state(S.SWITCH_ON_DISABLED)
                self.emcy(0x0000, fault=False)
            return
        if s is S.FAULT_REACTION_ACTIVE or cw & 0x80:
            return
        if cw & 0x02 == 0:  # disable voltage
            if s is not S.SWITCH_ON_DISABLED:
                self._set_state(S.SWITCH_ON_DISABLED)
        elif cw & 0x06 == 0x02:  # quick stop
            if s is S.OPERATION_ENABLED:
                self._start_quick_stop()
            elif s in (S.READY_TO_SWITCH_ON, S.SWITCHED_ON):
                self._set_state(S.SWITCH_ON_DISABLED)
        elif cw & 0x07 == 0x06:  # shutdown
            if s in (S.SWITCH_ON_DISABLED, S.SWITCHED_ON, S.OPERATION_ENABLED):
                self._set_state(S.READY_TO_SWITCH_ON)
        elif cw & 0x0F == 0x07:  # switch on / disable operation
            if s in (S.READY_TO_SWITCH_ON, S.OPERATION_ENABLED):
                self._set_state(S.SWITCHED_ON)
        elif cw & 0x0F == 0x0F and (s in (S.READY_TO_SWITCH_ON, S.SWITCHED_ON) or (
                s is S.QUICK_STOP_ACTIVE and cw != previous
                and self._value(o.QUICK_STOP_OPTION, 0) in _QS_HOLD_OPTIONS)):
            self._set_state(S.OPERATION_ENABLED)  # enable operation
        if self.state is S.OPERATION_ENABLED and self.mode_display == o.HOMING_MODE:
            self.homing.on_controlword(previous, cw)

    def _set_state(self, state: DriveState) -> None:
        powered_before = self.powered
        self.state = state
        self.powered = state in _POWERED
        if state is DriveState.OPERATION_ENABLED:
            self.motor.hold()
            self._internal_target_deg = self.motor.position_deg
            self.target_counts = self.position_counts
            self.mode_display = self.mode
        elif not self.powered and powered_before:
            self.velocity_counts_s = 0
        if state is not DriveState.OPERATION_ENABLED and self.homing.active:
            self.homing.interrupt()  # a search never resumes by itself on the next enable
        self._update_statusword()

    def _start_quick_stop(self) -> None:
        self._qs_velocity_deg_s = self.motor.velocity_deg_s
        option = self._value(o.QUICK_STOP_OPTION, 0)
        self._set_state(DriveState.SWITCH_ON_DISABLED if option == 0
                        else DriveState.QUICK_STOP_ACTIVE)

    def fault(self, code: int) -> None:
        """Enter FAULT REACTION ACTIVE with ``code`` in 0x603F and send the EMCY."""
        if self.state in (DriveState.FAULT, DriveState.FAULT_REACTION_ACTIVE):
            return
        self.error_code = code
        self._qs_velocity_deg_s = self.motor.velocity_deg_s
        self.emcy(code, fault=True)
        self._set_state(DriveState.FAULT_REACTION_ACTIVE)

    def emcy(self, code: int, fault: bool = True, register: int | None = None) -> None:
        """Send an EMCY frame (code, error register, 5 manufacturer bytes)."""
        if fault:
            self.error_register |= 0x01 | (0x10 if code >> 12 == 0x8 else 0)
        reg = self.error_register if register is None else register
        self._emit(0x80 + self.node_id, struct.pack("<HB5s", code, reg, b"\x00" * 5))


    def _update_statusword(self) -> None:
        key = (self.state, self.halted, self.internal_limit, self.following_error,
               bool(self.error_register))
        if key == self._sw_key:  # compared member by member: no enum hash per tick
            sw = self._sw_base
        else:
            known = _STATUSWORDS.get(key)
            sw = known if known is not None else _statusword(*key)
            _STATUSWORDS[key] = sw
            self._sw_key, self._sw_base = key, sw
        if self.mode_display == o.HOMING_MODE:  # bits 10, 12, 13 mean homing progress here
            sw = (sw & ~HOMING_BITS) | self.homing.bits
        self.statusword = sw
