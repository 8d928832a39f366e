"""The control loop's vocabulary: states, errors, the per-tick sample, commands, playback.

Kept apart from :mod:`tsmd.loop` so the API, replay and online code can name what a tick
produces without reading the loop itself.
"""

from __future__ import annotations

import enum
import math
import struct
import threading
from concurrent.futures import Future
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from tsmd.errors import TsmdError

Array = NDArray[np.float64]

ROW_COLUMNS: tuple[str, ...] = (
    "t", "q1", "q2", "cmd1", "cmd2", "pos1", "pos2", "cur1", "cur2", "tip1", "tip2",
)
"""The recording columns every tick produces (tsmd.recording.REQUIRED_COLUMNS)."""
ROW = struct.Struct(f"@{len(ROW_COLUMNS)}d")
"""One row packed as native float64s, as a trajectory's rows are kept while it plays."""


class LoopState(enum.Enum):
    DISABLED = "DISABLED"
    ENABLED = "ENABLED"
    FAULT = "FAULT"


class LoopError(TsmdError):
    """A loop command could not be carried out; the message says why."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(message)
        self.code = code


class TickRecorder(Protocol):
    def append(self, row: tuple[float, ...]) -> None: ...


@dataclass(frozen=True)
class Sample:
    """What one tick did; published to the API (``get``, ``subscribe``)."""

    tick: int
    t_s: float
    state: LoopState
    q_deg: tuple[float, float]
    cmd_deg: tuple[float, float]
    pos_deg: tuple[float, float]
    current_A: tuple[float, float]
    tip_deg: tuple[float, float]
    fault: str | None

    @classmethod
    def from_row(cls, tick: int, t_s: float, state: LoopState, row: tuple[float, ...],
                 fault: str | None) -> Sample:
        """The sample of a recorded row (columns :data:`ROW_COLUMNS`)."""
        return cls(tick, t_s, state, (row[1], row[2]), (row[3], row[4]), (row[5], row[6]),
                   (row[7], row[8]), (row[9], row[10]), fault)

    def as_dict(self) -> dict[str, Any]:
        def clean(values: tuple[float, float]) -> list[float | None]:
            return [v if math.isfinite(v) else None for v in values]

        return {"tick": self.tick, "t": self.t_s, "state": self.state.value,
                "q": clean(self.q_deg), "cmd": clean(self.cmd_deg), "pos": clean(self.pos_deg),
                "cur": clean(self.current_A), "tip": clean(self.tip_deg), "fault": self.fault}


class LatestSetpoint:
    """The one value the API writes and the loop reads: replaced whole, never mutated."""

    def __init__(self) -> None:
        self._value: tuple[float, float] | None = None
        self.version = 0

    def set(self, q_deg: tuple[float, float]) -> None:
        self._value = (float(q_deg[0]), float(q_deg[1]))
        self.version += 1

    def clear(self) -> None:
        self._value = None

    def get(self) -> tuple[float, float] | None:
        return self._value


@dataclass
class LoopCommand:
    """A request from another thread, executed by the loop thread between two ticks."""

    name: str
    args: dict[str, Any] = field(default_factory=dict)
    future: Future[Any] = field(default_factory=Future)


@dataclass
class Playback:
    """A trajectory the loop plays one sample per tick, recording each tick into ``rows``."""

    q_deg: Array
    compensate: bool
    cancel: threading.Event | None = None
    rows: bytearray = field(default_factory=bytearray)
    """Every recorded row packed with :data:`ROW`, one after the other: no Python object per
    tick, and read back by :meth:`table` without a conversion."""
    index: int = 0
    done: threading.Event = field(default_factory=threading.Event)
    error: str | None = None

    @property
    def progress(self) -> float:
        return self.index / max(len(self.q_deg), 1)

    def table(self) -> Array:
        """The recorded rows, shape (ticks, len(ROW_COLUMNS)), viewing :attr:`rows` (read it
        once the playback is done: the buffer cannot grow while viewed)."""
        return np.frombuffer(self.rows, dtype=np.float64).reshape(-1, len(ROW_COLUMNS))


@dataclass
class LoopStats:
    ticks: int = 0
    overruns: int = 0
    overrun_streak: int = 0
    faults: int = 0
