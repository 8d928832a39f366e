"""The loop's fault rules (tsmd.loop_supervision), without a loop."""

from __future__ import annotations

import math

from drivers.drive import DriveFeedback, DriveState, FaultEvent, FaultKind
from tsmd.loop_supervision import tick_fault


def _fb(state: DriveState = DriveState.OPERATION_ENABLED, age: int = 0,
        pos: float = 0.0, cur: float = 0.1) -> DriveFeedback:
    return DriveFeedback(position_deg=pos, current_A=cur, statusword=0x27, state=state,
                         age_syncs=age)


def _check(feedback: list[DriveFeedback], events: list[FaultEvent] | None = None,
           streak: int = 0) -> str | None:
    return tick_fault(events or [], feedback, stale_feedback_syncs=3, overrun_streak=streak,
                      overrun_fault_streak=5)


def test_healthy_drives_give_no_fault() -> None:
    assert _check([_fb(), _fb()]) is None


def test_a_drive_event_is_the_fault_and_names_its_drive() -> None:
    event = FaultEvent(FaultKind.EMCY, 1, 0.0, "over-current")
    assert _check([_fb(), _fb()], [event]) == "drive 1: emcy: over-current"


def test_a_drive_that_left_operation_enabled_is_a_fault() -> None:
    reason = _check([_fb(), _fb(state=DriveState.SWITCHED_ON)])
    assert reason is not None and reason.startswith("drive 1: left OPERATION ENABLED")


def test_feedback_older_than_the_allowed_syncs_is_a_fault() -> None:
    assert _check([_fb(age=3), _fb()]) is None
    assert "stale feedback (4 SYNCs" in str(_check([_fb(age=4), _fb()]))


def test_non_finite_feedback_is_a_fault() -> None:
    assert "non-finite feedback" in str(_check([_fb(), _fb(cur=math.nan)]))


def test_too_many_overruns_in_a_row_is_a_fault() -> None:
    assert _check([_fb(), _fb()], streak=4) is None
    assert _check([_fb(), _fb()], streak=5) == "5 overruns in a row"
