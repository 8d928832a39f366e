"""SocketCAN error frames, decoded into named bus events (constants of linux/can/error.h).

The kernel reports controller and bus problems as error frames: ``can.Message.is_error_frame``
with the error class bits in the identifier and details in the 8 data bytes. python-can's
``socketcan`` interface subscribes to all of them. :func:`decode_error_frame` turns one into a
:class:`BusErrorReport`: what happened, in words, and the controller state it implies.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

import can

# error class, in the CAN id
CAN_ERR_TX_TIMEOUT = 0x001
CAN_ERR_LOSTARB = 0x002
CAN_ERR_CRTL = 0x004
CAN_ERR_PROT = 0x008
CAN_ERR_TRX = 0x010
CAN_ERR_ACK = 0x020
CAN_ERR_BUSOFF = 0x040
CAN_ERR_BUSERROR = 0x080
CAN_ERR_RESTARTED = 0x100
CAN_ERR_CNT = 0x200

# data[1]: controller status
CAN_ERR_CRTL_RX_OVERFLOW = 0x01
CAN_ERR_CRTL_TX_OVERFLOW = 0x02
CAN_ERR_CRTL_RX_WARNING = 0x04
CAN_ERR_CRTL_TX_WARNING = 0x08
CAN_ERR_CRTL_RX_PASSIVE = 0x10
CAN_ERR_CRTL_TX_PASSIVE = 0x20
CAN_ERR_CRTL_ACTIVE = 0x40

_CLASSES = (
    (CAN_ERR_TX_TIMEOUT, "TX timeout"),
    (CAN_ERR_LOSTARB, "lost arbitration"),
    (CAN_ERR_CRTL, "controller problem"),
    (CAN_ERR_PROT, "protocol violation"),
    (CAN_ERR_TRX, "transceiver problem"),
    (CAN_ERR_ACK, "no ACK on transmission (no other node on the bus?)"),
    (CAN_ERR_BUSOFF, "bus-off"),
    (CAN_ERR_BUSERROR, "bus error"),
    (CAN_ERR_RESTARTED, "controller restarted"),
)
_CONTROLLER = (
    (CAN_ERR_CRTL_RX_OVERFLOW, "RX buffer overflow"),
    (CAN_ERR_CRTL_TX_OVERFLOW, "TX buffer overflow"),
    (CAN_ERR_CRTL_RX_WARNING, "RX error warning level"),
    (CAN_ERR_CRTL_TX_WARNING, "TX error warning level"),
    (CAN_ERR_CRTL_RX_PASSIVE, "RX error passive"),
    (CAN_ERR_CRTL_TX_PASSIVE, "TX error passive"),
    (CAN_ERR_CRTL_ACTIVE, "back to error active"),
)
_PROTOCOL = (
    (0x01, "single bit error"), (0x02, "frame format error"), (0x04, "bit stuffing error"),
    (0x08, "unable to send dominant bit"), (0x10, "unable to send recessive bit"),
    (0x20, "bus overload"), (0x40, "active error announcement"),
    (0x80, "error on transmission"),
)
_TRANSCEIVER = {
    0x04: "CANH no wire", 0x05: "CANH short to BAT", 0x06: "CANH short to VCC",
    0x07: "CANH short to GND", 0x40: "CANL no wire", 0x50: "CANL short to BAT",
    0x60: "CANL short to VCC", 0x70: "CANL short to GND", 0x80: "CANL short to CANH",
}


class BusState(enum.Enum):
    """Fault confinement state of our CAN controller (ISO 11898-1)."""

    ERROR_ACTIVE = "error active"
    ERROR_WARNING = "error warning"
    ERROR_PASSIVE = "error passive"
    BUS_OFF = "bus-off"


@dataclass(frozen=True)
class BusErrorReport:
    """One decoded error frame."""

    classes: tuple[str, ...]
    """Names of the error classes set, e.g. ``("controller problem",)``."""
    details: tuple[str, ...]
    """What the data bytes say, e.g. ``("TX error passive",)``."""
    state: BusState | None
    """The controller state this frame announces (None: it announces none)."""
    tx_errors: int | None
    rx_errors: int | None

    @property
    def bus_off(self) -> bool:
        return self.state is BusState.BUS_OFF

    @property
    def restarted(self) -> bool:
        return "controller restarted" in self.classes

    def text(self) -> str:
        parts = ", ".join(self.classes) or "unspecified error"
        if self.details:
            parts += f" ({', '.join(self.details)})"
        if self.tx_errors is not None:
            parts += f", error counters TX {self.tx_errors} RX {self.rx_errors}"
        return parts


@dataclass(frozen=True)
class BusEvent:
    """What the master saw of the bus itself (not a drive): one decoded error frame."""

    t_s: float
    report: BusErrorReport
    message: str


def decode_error_frame(msg: can.Message) -> BusErrorReport:
    """Decode a SocketCAN error frame (``msg.is_error_frame``) per linux/can/error.h."""
    cls = msg.arbitration_id
    data = bytes(msg.data).ljust(8, b"\x00")
    classes = tuple(name for bit, name in _CLASSES if cls & bit)
    details: list[str] = []
    state: BusState | None = None
    if cls & CAN_ERR_LOSTARB and data[0]:
        details.append(f"arbitration lost at bit {data[0]}")
    if cls & CAN_ERR_CRTL:
        details += [name for bit, name in _CONTROLLER if data[1] & bit]
        if data[1] & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE):
            state = BusState.ERROR_PASSIVE
        elif data[1] & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING):
            state = BusState.ERROR_WARNING
        elif data[1] & CAN_ERR_CRTL_ACTIVE:
            state = BusState.ERROR_ACTIVE
    if cls & CAN_ERR_PROT:
        details += [name for bit, name in _PROTOCOL if data[2] & bit]
        if data[3]:
            details.append(f"at location 0x{data[3]:02X}")
    if cls & CAN_ERR_TRX and data[4]:
        details.append(_TRANSCEIVER.get(data[4], f"transceiver status 0x{data[4]:02X}"))
    if cls & CAN_ERR_RESTARTED:
        state = BusState.ERROR_ACTIVE
    if cls & CAN_ERR_BUSOFF:
        state = BusState.BUS_OFF
    counters = bool(cls & CAN_ERR_CNT) or bool(cls & CAN_ERR_CRTL and (data[6] or data[7]))
    return BusErrorReport(classes, tuple(details), state,
                          data[6] if counters else None, data[7] if counters else None)


def error_frame(classes: int, data: bytes = b"") -> can.Message:
    """An error frame as SocketCAN delivers it (for simulation and tests)."""
    return can.Message(arbitration_id=classes, data=bytes(data).ljust(8, b"\x00"),
                       is_error_frame=True, is_extended_id=False)
