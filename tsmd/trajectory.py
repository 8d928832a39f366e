"""The contract between whoever plans knob trajectories (calibration, benchmarks) and the loop.

A :class:`TrajectoryRunner` plays desired knob angles one sample per loop tick and records
every tick; it says at which period it ticks, so that a planner never assumes one.
Implementations: :class:`tsmd.replay.LockstepRunner` (simulated rig, deterministic) and
:class:`tsmd.replay.LiveTrajectoryRunner` (the daemon's running loop).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Protocol

from numpy.typing import ArrayLike

from tsmd.recording import Recording

ProgressFn = Callable[[float], None]
"""Called with the fraction (0..1) of the trajectory played so far."""


class TrajectoryRunner(Protocol):
    """Plays desired knob angles ``q_deg`` (N, 2) at times ``t_s`` and records each tick.

    The trajectory is resampled at the runner's tick times ``t0 + k * period_s``. When
    ``cancel`` is set the run stops at the next tick and returns what it recorded so far
    (metadata ``cancelled: true``); a fault on the way raises a :class:`tsmd.errors.TsmdError`.
    """

    @property
    def period_s(self) -> float:
        """The loop period the trajectory is played at."""

    def run(self, t_s: ArrayLike, q_deg: ArrayLike, compensate: bool,
            cancel: threading.Event | None = None,
            progress: ProgressFn | None = None) -> Recording: ...
