"""CiA 402 power state machine: statusword decoding and controlword commands.

Shared by the master (to decide the next command) and the simulated drive (to encode its state).
"""

from __future__ import annotations

from drivers.drive import DriveState

# Controlword commands (bits 0..3 and 7)
CW_DISABLE_VOLTAGE = 0x0000
CW_SHUTDOWN = 0x0006
CW_SWITCH_ON = 0x0007
CW_ENABLE_OPERATION = 0x000F
CW_QUICK_STOP = 0x0002
CW_FAULT_RESET = 0x0080
CW_HALT = 0x0100
CW_HOMING_START = 0x0010
"""Homing Mode: a rising edge starts homing, clearing it interrupts (operation-mode bit 4)."""

# Statusword bits
SW_READY_TO_SWITCH_ON = 0x0001
SW_SWITCHED_ON = 0x0002
SW_OPERATION_ENABLED = 0x0004
SW_FAULT = 0x0008
SW_VOLTAGE_ENABLED = 0x0010
SW_QUICK_STOP = 0x0020
"""Set when quick stop is NOT active."""
SW_SWITCH_ON_DISABLED = 0x0040
SW_WARNING = 0x0080
SW_REMOTE = 0x0200
SW_TARGET_REACHED = 0x0400
SW_INTERNAL_LIMIT = 0x0800
SW_FOLLOWS_TARGET = 0x1000
"""CSP: the drive follows the target position."""
SW_FOLLOWING_ERROR = 0x2000
SW_HOMING_ATTAINED = 0x1000
"""Homing Mode meaning of bit 12 (bits 12/13 are operation-mode specific)."""
SW_HOMING_ERROR = 0x2000
"""Homing Mode meaning of bit 13."""

STATE_BITS: dict[DriveState, int] = {
    DriveState.NOT_READY_TO_SWITCH_ON: 0x0000,
    DriveState.SWITCH_ON_DISABLED: 0x0040,
    DriveState.READY_TO_SWITCH_ON: 0x0021,
    DriveState.SWITCHED_ON: 0x0023,
    DriveState.OPERATION_ENABLED: 0x0027,
    DriveState.QUICK_STOP_ACTIVE: 0x0007,
    DriveState.FAULT_REACTION_ACTIVE: 0x000F,
    DriveState.FAULT: 0x0008,
}

_DECODE: list[tuple[int, int, DriveState]] = [
    (0x4F, 0x00, DriveState.NOT_READY_TO_SWITCH_ON),
    (0x4F, 0x40, DriveState.SWITCH_ON_DISABLED),
    (0x6F, 0x21, DriveState.READY_TO_SWITCH_ON),
    (0x6F, 0x23, DriveState.SWITCHED_ON),
    (0x6F, 0x27, DriveState.OPERATION_ENABLED),
    (0x6F, 0x07, DriveState.QUICK_STOP_ACTIVE),
    (0x4F, 0x0F, DriveState.FAULT_REACTION_ACTIVE),
    (0x4F, 0x08, DriveState.FAULT),
]
_CACHE: dict[int, DriveState] = {}


def decode_state(statusword: int) -> DriveState:
    """The power state encoded in a statusword (CiA 402 table of state bits)."""
    state = _CACHE.get(statusword)
    if state is None:
        state = DriveState.UNKNOWN
        for mask, value, candidate in _DECODE:
            if statusword & mask == value:
                state = candidate
                break
        _CACHE[statusword] = state
    return state


def next_command_to_enable(state: DriveState, quick_stop_option: int = 6,
                           controlword: int = 0) -> int | None:
    """Controlword that moves one step towards OPERATION ENABLED (None: cannot, e.g. FAULT).

    From QUICK STOP ACTIVE the drive may go straight back (options 5..8) on a fresh
    "enable operation" command, so a controlword still saying "enable" is first turned into
    "quick stop"; otherwise it must pass through SWITCH ON DISABLED.
    """
    if state is DriveState.QUICK_STOP_ACTIVE and quick_stop_option in (5, 6, 7, 8):
        if controlword & 0x0F == CW_ENABLE_OPERATION:
            return CW_QUICK_STOP
        return CW_ENABLE_OPERATION
    return {
        DriveState.SWITCH_ON_DISABLED: CW_SHUTDOWN,
        DriveState.READY_TO_SWITCH_ON: CW_SWITCH_ON,
        DriveState.SWITCHED_ON: CW_ENABLE_OPERATION,
        DriveState.OPERATION_ENABLED: CW_ENABLE_OPERATION,
        DriveState.QUICK_STOP_ACTIVE: CW_DISABLE_VOLTAGE,
    }.get(state)
