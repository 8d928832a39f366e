"""A small in-memory KnobDrives for the loop and API tests (no CAN, no physics).

Each SYNC moves the knob to the last target (an ideal drive) and ages nothing; tests flip its
fields to produce faults. Every target written is kept, so tests can assert limits.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from drivers.drive import DriveError, DriveFeedback, DriveState, FaultEvent, FaultKind, KnobDrives
from simrig.rig import open_sim_rig
from support.plants import SpringPlant


class FakeDrives(KnobDrives):
    def __init__(self) -> None:
        self.pos = [0.0, 0.0]
        self.state = DriveState.SWITCH_ON_DISABLED
        self.targets: list[tuple[float, float]] = []
        self.pending: tuple[float, float] | None = None
        self.events: list[FaultEvent] = []
        self.silent = False
        self.age = 0
        self.calls: list[str] = []
        self.enable_fails = False
        self.heartbeat_missing = [False, False]

    @property
    def count(self) -> int:
        return 2

    def boot(self) -> None:
        self.calls.append("boot")

    def enable(self) -> None:
        self.calls.append("enable")
        if self.enable_fails:
            raise DriveError("drive 0: enable timed out in SWITCHED ON")
        self.state = DriveState.OPERATION_ENABLED

    def disable(self) -> None:
        self.calls.append("disable")
        if self.state is not DriveState.FAULT:
            self.state = DriveState.SWITCH_ON_DISABLED

    def quick_stop(self) -> None:
        self.calls.append("quick_stop")
        if self.state is DriveState.OPERATION_ENABLED:
            self.state = DriveState.QUICK_STOP_ACTIVE

    def halt(self, on: bool) -> None:
        self.calls.append(f"halt {on}")

    def fault_reset(self) -> None:
        self.calls.append("fault_reset")
        if self.state is DriveState.FAULT:
            self.state = DriveState.SWITCH_ON_DISABLED

    def write_targets(self, knob_deg: Sequence[float]) -> None:
        self.pending = (float(knob_deg[0]), float(knob_deg[1]))
        self.targets.append(self.pending)

    def sync(self) -> None:
        if self.silent:
            self.age += 1
            return
        self.age = 0
        if self.pending is not None and self.state is DriveState.OPERATION_ENABLED:
            self.pos = list(self.pending)

    def pump(self) -> None:
        pass

    def feedback(self) -> list[DriveFeedback]:
        return [DriveFeedback(p, 0.1 * p / 90.0, 0x27, self.state, self.age) for p in self.pos]

    def poll_events(self) -> list[FaultEvent]:
        events, self.events = self.events, []
        return events

    def close(self) -> None:
        self.calls.append("close")

    def heartbeat_lost(self) -> list[bool]:
        return list(self.heartbeat_missing)

    def lose_heartbeat(self, drive: int = 0) -> None:
        """What the master reports once when a drive's heartbeat stops."""
        self.heartbeat_missing[drive] = True
        self.events.append(FaultEvent(FaultKind.HEARTBEAT_LOST, drive, 0.0,
                                      "no heartbeat for 0.150 s"))

    def emcy(self, drive: int = 0) -> None:
        """What the real master reports for an EMCY: an event and the drive in FAULT."""
        self.events.append(FaultEvent(FaultKind.EMCY, drive, 0.0, "EMCY 0x8611 following error",
                                      0x8611))
        self.state = DriveState.FAULT

    def targets_array(self) -> np.ndarray:
        return np.array(self.targets, dtype=float).reshape(-1, 2)


def open_enabled_rig(seed: int, period_s: float = 0.004) -> tuple[Any, Any]:
    """Two simulated drives on a spring plant, booted and enabled, with no fault pending."""
    drives, rig = open_sim_rig(SpringPlant(), None, period_s, seed=seed)
    drives.boot()
    drives.enable()
    assert drives.poll_events() == []
    return drives, rig


def tick(drives: Any, rig: Any, q: Sequence[float] = (0.0, 0.0), n: int = 1) -> None:
    """``n`` lockstep ticks of the master and the rig with the knob targets ``q``."""
    for _ in range(n):
        drives.write_targets(q)
        drives.sync()
        rig.exchange()
        drives.pump()
