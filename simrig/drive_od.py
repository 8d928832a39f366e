"""The simulated drive's object dictionary: SDO object store and PDO layouts.

Split from :mod:`simrig.drive_node` as a mix-in of :class:`~simrig.drive_node.SimDriveNode`:
canopen's ``SdoServer`` calls ``get_data`` / ``set_data``, and every
accepted write recompiles the PDO layouts and the cached drive parameters.
"""

from __future__ import annotations

import operator
import struct
from collections.abc import Callable
from typing import Any

import canopen
from canopen.objectdictionary import ODVariable
from canopen.sdo import SdoAbortedError

from drivers import od as o
from simrig.motor import Motor

_FORMATS = {1: "?", 2: "b", 3: "h", 4: "i", 5: "B", 6: "H", 7: "I"}

# PDO-mappable live values: object index -> attribute of SimDriveNode
_LIVE: dict[int, str] = {
    o.STATUSWORD: "statusword",
    o.POSITION_ACTUAL: "position_counts",
    o.CURRENT_ACTUAL: "current_raw",
    o.VELOCITY_ACTUAL: "velocity_counts_s",
    o.FOLLOWING_ERROR_ACTUAL: "following_error_counts",
    o.MODES_OF_OPERATION_DISPLAY: "mode_display",
    o.ERROR_CODE: "error_code",
    o.ERROR_REGISTER: "error_register",
    o.CONTROLWORD: "controlword",
    o.TARGET_POSITION: "target_counts",
}


class DriveObjectStore:
    """Object values of one simulated drive, typed by the EDS; the node supplies the state."""

    od: Any
    values: dict[tuple[int, int], Any]
    _defaults: dict[tuple[int, int], Any]
    counts_per_deg: float
    motor: Motor
    mode: int
    mode_display: int
    target_counts: int
    homing: Any

    def write_controlword(self, cw: int) -> None:
        raise NotImplementedError

    def hold_position(self) -> None:
        raise NotImplementedError

    def _update_statusword(self) -> None:
        raise NotImplementedError

    # -- PDO configuration ----------------------------------------------------------------
    def _configure_pdos(self) -> None:
        """Compile the PDO layouts (0x1400/0x1600, 0x1800/0x1A00) and cache hot parameters."""
        cpd = self.counts_per_deg
        self._limit_lo = self._value(o.SOFTWARE_POSITION_LIMIT, 1)
        self._limit_hi = self._value(o.SOFTWARE_POSITION_LIMIT, 2)
        self._vmax_deg_s = self._value(o.MAX_PROFILE_VELOCITY, 0) / cpd
        self._qs_decel_deg_s2 = self._value(o.QUICK_STOP_DECELERATION, 0) / cpd
        self._raw_per_A = 1e6 / max(1, self._value(o.MOTOR_RATED_CURRENT, 0))
        self._master_timeout_s = (self._value(o.CONSUMER_HEARTBEAT, 1) & 0xFFFF) * 1e-3
        self._fe_window = self._value(o.FOLLOWING_ERROR_WINDOW, 0)
        self._fe_timeout_s = self._value(o.FOLLOWING_ERROR_TIMEOUT, 0) * 1e-3
        self._hb_period_ms = self._value(o.PRODUCER_HEARTBEAT, 0)
        self.motor.limit_speed(self._value(o.MAX_MOTOR_SPEED, 0))
        hb = self._value(o.CONSUMER_HEARTBEAT, 1)
        self._master_hb_cob = 0x700 + ((hb >> 16) & 0x7F) if hb else -1
        cob = self._value(o.RPDO1_COMM, 1)
        self._rpdo_cob = -1 if cob & 0x80000000 else cob & 0x7FF
        self._rpdo_sync = self._value(o.RPDO1_COMM, 2) <= 240
        fmt, attrs = self._layout(o.RPDO1_MAP, rpdo=True)
        self._rpdo_struct = struct.Struct(fmt)
        self._rpdo_len = self._rpdo_struct.size
        self._rpdo_attrs = attrs
        self._rpdo_csp = attrs == ["controlword", "target_counts"]
        cob = self._value(o.TPDO1_COMM, 1)
        self._tpdo_cob = None if cob & 0x80000000 else cob & 0x7FF
        trans = self._value(o.TPDO1_COMM, 2)
        self._tpdo_every = trans if 1 <= trans <= 240 else 0
        fmt, attrs = self._layout(o.TPDO1_MAP, rpdo=False)
        self._tpdo_struct = struct.Struct(fmt)
        self._tpdo_attrs = attrs
        get = operator.attrgetter(*attrs) if attrs else (lambda node: ())
        self._tpdo_values: Callable[[Any], Any] = (
            (lambda node: (get(node),)) if len(attrs) == 1 else get)

    def _layout(self, map_index: int, rpdo: bool) -> tuple[str, list[str]]:
        fmt = "<"
        attrs: list[str] = []
        for sub in range(1, self._value(map_index, 0) + 1):
            entry = self._value(map_index, sub)
            index, subindex = entry >> 16, (entry >> 8) & 0xFF
            var = self._variable(index, subindex)
            fmt += _FORMATS[int(var.data_type or 0)]
            attrs.append("mode" if index == o.MODES_OF_OPERATION else _LIVE[index])
        return fmt, attrs

    # -- object store (canopen's SdoServer calls these) ------------------------------------
    def _variable(self, index: int, subindex: int) -> ODVariable:
        if index not in self.od:
            raise SdoAbortedError(0x06020000)
        obj = self.od[index]
        if not isinstance(obj, ODVariable):
            if subindex not in obj:
                raise SdoAbortedError(0x06090011)
            obj = obj[subindex]
        return obj

    def _value(self, index: int, subindex: int) -> Any:
        key = (index, subindex)
        if key in self.values:
            return self.values[key]
        if key in self._defaults:
            return self._defaults[key]
        var = self._variable(index, subindex)
        return var.default

    def get_data(self, index: int, subindex: int, check_readable: bool = False) -> bytes:
        var = self._variable(index, subindex)
        if check_readable and not var.readable:
            raise SdoAbortedError(0x06010001)
        if index == o.MODES_OF_OPERATION:
            return var.encode_raw(self.mode)
        attr = _LIVE.get(index)
        value = getattr(self, attr) if attr is not None else self._value(index, subindex)
        return var.encode_raw(value)

    def set_data(self, index: int, subindex: int, data: bytes,
                 check_writable: bool = False) -> None:
        var = self._variable(index, subindex)
        if check_writable and not var.writable:
            raise SdoAbortedError(0x06010002)
        if var.data_type in canopen.objectdictionary.NUMBER_TYPES and 8 * len(data) != len(var):
            raise SdoAbortedError(0x06070010)
        value: Any = var.decode_raw(data)
        if var.min is not None and value < var.min:
            raise SdoAbortedError(0x06090032)
        if var.max is not None and value > var.max:
            raise SdoAbortedError(0x06090031)
        if index in (o.RPDO1_MAP, o.TPDO1_MAP) and subindex >= 1:
            self._check_mappable(value, rpdo=index == o.RPDO1_MAP)
        if index in (o.RPDO1_MAP, o.TPDO1_MAP) and subindex == 0:
            self._check_mapping_length(index, value)
        if index == o.MODES_OF_OPERATION and value not in (0, o.CSP_MODE, o.HOMING_MODE):
            raise SdoAbortedError(0x06090030)
        if index == o.CONTROLWORD:
            self.write_controlword(value)
            return
        if index == o.TARGET_POSITION:
            self.target_counts = value
            return
        if index == o.MODES_OF_OPERATION:
            if value != self.mode_display:
                self.homing.clear()
                self.hold_position()  # a mode change never moves the motor
            self.mode = self.mode_display = value
            self._update_statusword()
            return
        self.values[(index, subindex)] = value
        self._configure_pdos()

    def _check_mappable(self, entry: int, rpdo: bool) -> None:
        if entry == 0:
            return
        index, subindex, bits = entry >> 16, (entry >> 8) & 0xFF, entry & 0xFF
        try:
            var = self._variable(index, subindex)
        except SdoAbortedError:
            raise SdoAbortedError(0x06040041) from None
        live_ok = index == o.MODES_OF_OPERATION or index in _LIVE
        if not var.pdo_mappable or not live_ok or bits != len(var) or (
                rpdo and index not in (o.CONTROLWORD, o.TARGET_POSITION,
                                       o.MODES_OF_OPERATION)):
            raise SdoAbortedError(0x06040041)

    def _check_mapping_length(self, map_index: int, count: int) -> None:
        bits = 0
        for sub in range(1, count + 1):
            entry = self._value(map_index, sub)
            if entry == 0:
                raise SdoAbortedError(0x06040043)
            bits += entry & 0xFF
        if bits > 64:
            raise SdoAbortedError(0x06040042)
