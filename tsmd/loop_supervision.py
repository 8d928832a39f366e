"""What the control loop counts as a fault: one place for the checks a tick, ``enable`` and
``reset`` make on the drives.

Plain functions of the drives' feedback and events, so the rules read in one screen and can be
tested without a loop. Each returns the reason as one line, or None when all is well.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from drivers.drive import DriveFeedback, DriveState, FaultEvent, KnobDrives

_OPERATION_ENABLED = DriveState.OPERATION_ENABLED  # read every tick: a global, not an enum lookup


def tick_fault(events: Sequence[FaultEvent], feedback: Sequence[DriveFeedback],
               stale_feedback_syncs: int, overrun_streak: int,
               overrun_fault_streak: int) -> str | None:
    """Why an ENABLED loop must stop now: a drive event, a drive that left OPERATION ENABLED,
    stale or non-finite feedback, or too many overruns in a row."""
    if events:
        ev = events[0]
        return f"drive {ev.drive}: {ev.kind.value}: {ev.message}"
    for i, fb in enumerate(feedback):
        if fb.state is not _OPERATION_ENABLED:
            return f"drive {i}: left OPERATION ENABLED (state {fb.state.value})"
        if fb.age_syncs > stale_feedback_syncs:
            return f"drive {i}: stale feedback ({fb.age_syncs} SYNCs without an answer)"
        if not (math.isfinite(fb.position_deg) and math.isfinite(fb.current_A)):
            return (f"drive {i}: non-finite feedback (position {fb.position_deg}, "
                    f"current {fb.current_A})")
    if overrun_streak >= overrun_fault_streak:
        return f"{overrun_streak} overruns in a row"
    return None


def silent_drive(drives: KnobDrives) -> str | None:
    """A drive whose heartbeat is lost: nothing may be enabled while one is."""
    for i, lost in enumerate(drives.heartbeat_lost()):
        if lost:
            return f"drive {i} sends no heartbeat"
    return None


def remaining_fault_cause(drives: KnobDrives, stale_feedback_syncs: int) -> str | None:
    """Why a fault cannot be reset yet (after the drives were told to reset and pumped)."""
    pending = drives.poll_events()
    if pending:
        ev = pending[0]
        return f"drive {ev.drive}: {ev.kind.value}: {ev.message}"
    for i, fb in enumerate(drives.feedback()):
        if fb.age_syncs > stale_feedback_syncs:
            return f"drive {i} feedback is stale ({fb.age_syncs} SYNCs)"
        if fb.state in (DriveState.FAULT, DriveState.FAULT_REACTION_ACTIVE):
            return f"drive {i} is in {fb.state.value}"
    return silent_drive(drives)
