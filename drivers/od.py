"""Our object dictionary (``tsmd_drive.eds``) and the CiA 301 code tables for messages.

The EDS is written for tsmd from the CiA 301/402 object definitions; both the master and the
simulated drive read object metadata from it through canopen's ``import_od``.
"""

from __future__ import annotations

from pathlib import Path

import canopen

EDS_PATH = Path(__file__).with_name("tsmd_drive.eds")

# Communication objects (CiA 301)
DEVICE_TYPE = 0x1000
ERROR_REGISTER = 0x1001
COB_ID_SYNC = 0x1005
CYCLE_PERIOD = 0x1006
CONSUMER_HEARTBEAT = 0x1016
PRODUCER_HEARTBEAT = 0x1017
IDENTITY = 0x1018
RPDO1_COMM = 0x1400
RPDO2_COMM = 0x1401
RPDO1_MAP = 0x1600
TPDO1_COMM = 0x1800
TPDO2_COMM = 0x1801
TPDO1_MAP = 0x1A00

# Manufacturer-specific objects
HOMING_CURRENT_THRESHOLD = 0x2080
"""mA; the hard stop of homing methods -3/-4 is where the current exceeds it."""

# Drive profile objects (CiA 402)
ABORT_CONNECTION_OPTION = 0x6007
ERROR_CODE = 0x603F
CONTROLWORD = 0x6040
STATUSWORD = 0x6041
QUICK_STOP_OPTION = 0x605A
MODES_OF_OPERATION = 0x6060
MODES_OF_OPERATION_DISPLAY = 0x6061
POSITION_ACTUAL = 0x6064
FOLLOWING_ERROR_WINDOW = 0x6065
FOLLOWING_ERROR_TIMEOUT = 0x6066
VELOCITY_ACTUAL = 0x606C
MOTOR_RATED_CURRENT = 0x6075
CURRENT_ACTUAL = 0x6078
TARGET_POSITION = 0x607A
HOME_OFFSET = 0x607C
SOFTWARE_POSITION_LIMIT = 0x607D
MAX_PROFILE_VELOCITY = 0x607F
MAX_MOTOR_SPEED = 0x6080
QUICK_STOP_DECELERATION = 0x6085
HOMING_METHOD = 0x6098
HOMING_SPEEDS = 0x6099
HOMING_ACCELERATION = 0x609A
INTERPOLATION_PERIOD = 0x60C2
FOLLOWING_ERROR_ACTUAL = 0x60F4
SUPPORTED_DRIVE_MODES = 0x6502

CSP_MODE = 8
HOMING_MODE = 6
DEVICE_PROFILE_402 = 402

RPDO1_MAPPING: tuple[tuple[int, int, int], ...] = ((CONTROLWORD, 0, 16), (TARGET_POSITION, 0, 32))
"""Master -> drive each tick: controlword (U16), target position (I32): 6 bytes."""
TPDO1_MAPPING: tuple[tuple[int, int, int], ...] = (
    (STATUSWORD, 0, 16), (POSITION_ACTUAL, 0, 32), (CURRENT_ACTUAL, 0, 16))
"""Drive -> master at each SYNC: statusword (U16), position (I32), current (I16): 8 bytes."""
RPDO1_FORMAT = "<Hi"
TPDO1_FORMAT = "<Hih"


def load_od(node_id: int | None = None) -> canopen.ObjectDictionary:
    """Our EDS as a canopen object dictionary (``$NODEID`` resolved when given)."""
    return canopen.import_od(str(EDS_PATH), node_id)


def mapping_entry(index: int, subindex: int, bits: int) -> int:
    """A PDO mapping parameter value (CiA 301: index << 16 | subindex << 8 | length)."""
    return (index << 16) | (subindex << 8) | bits


SDO_ABORT_CODES: dict[int, str] = {
    0x05030000: "toggle bit not alternated",
    0x05040000: "SDO protocol timed out",
    0x05040001: "client/server command specifier not valid or unknown",
    0x05040002: "invalid block size",
    0x05040003: "invalid sequence number",
    0x05040004: "CRC error",
    0x05040005: "out of memory",
    0x06010000: "unsupported access to an object",
    0x06010001: "attempt to read a write only object",
    0x06010002: "attempt to write a read only object",
    0x06020000: "object does not exist in the object dictionary",
    0x06040041: "object cannot be mapped to the PDO",
    0x06040042: "number and length of mapped objects would exceed PDO length",
    0x06040043: "general parameter incompatibility",
    0x06040047: "general internal incompatibility in the device",
    0x06060000: "access failed due to a hardware error",
    0x06070010: "data type does not match, length of service parameter does not match",
    0x06070012: "data type does not match, length of service parameter too high",
    0x06070013: "data type does not match, length of service parameter too low",
    0x06090011: "sub-index does not exist",
    0x06090030: "invalid value for parameter",
    0x06090031: "value of parameter written too high",
    0x06090032: "value of parameter written too low",
    0x06090036: "maximum value is less than minimum value",
    0x060A0023: "resource not available: SDO connection",
    0x08000000: "general error",
    0x08000020: "data cannot be transferred or stored to the application",
    0x08000021: "data cannot be transferred because of local control",
    0x08000022: "data cannot be transferred because of the present device state",
    0x08000023: "object dictionary not present or dynamic generation failed",
    0x08000024: "no data available",
}


def abort_meaning(code: int) -> str:
    return SDO_ABORT_CODES.get(code, "unknown abort code")


_EMCY_EXACT: dict[int, str] = {
    0x0000: "error reset or no error",
    0x1000: "generic error",
    0x2310: "continuous over-current",
    0x3210: "DC link over-voltage",
    0x3220: "DC link under-voltage",
    0x4310: "drive over-temperature",
    0x5530: "data storage (non-volatile memory) error",
    0x6010: "software reset (watchdog)",
    0x7305: "incremental sensor 1 fault",
    0x8110: "CAN overrun (objects lost)",
    0x8120: "CAN in error passive mode",
    0x8130: "life guard error or heartbeat error",
    0x8140: "recovered from bus off",
    0x8210: "PDO not processed due to length error",
    0x8611: "following error",
    0x8612: "reference limit",
    0xFF00: "device specific",
}
_EMCY_CLASS: dict[int, str] = {
    0x1: "generic error", 0x2: "current", 0x3: "voltage", 0x4: "temperature",
    0x5: "device hardware", 0x6: "device software", 0x7: "additional modules",
    0x8: "monitoring", 0x9: "external error", 0xF: "additional functions",
}


def emcy_meaning(code: int) -> str:
    """Text for an EMCY / 0x603F error code: exact where known, else its CiA 301 class."""
    if code in _EMCY_EXACT:
        return _EMCY_EXACT[code]
    if code >= 0xFF00:
        return "device specific"
    return _EMCY_CLASS.get(code >> 12, "unknown") + " error"
