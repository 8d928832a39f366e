"""The running daemon's online worker: built for the active compensator, rebuilt with it.

The loop has one ``observer`` slot; :class:`OnlineAttachment` owns what sits in it. Whenever
the compensator is replaced (a profile, a method, a calibration) a new worker is built on the
new compensator, from the profile's own values (the old estimates were about the old
profile); until then the old worker only ever updates the old compensator object, which the
loop no longer uses.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol

from tsmd.config import OnlineConfig
from tsmd.loop import ROW_COLUMNS, TickRecorder
from tsmd.online.apply import ZERO_OFFSETS, OnlineError, save_online_version
from tsmd.online.bend import BendRelation
from tsmd.online.estimator_options import EstimatorOptions
from tsmd.online.worker import OnlineWorker
from tsmd.profile import CatheterProfile


class Observed(Protocol):
    """What the attachment needs of the loop: its per-tick hook, its period and why it faulted."""

    observer: Callable[[tuple[float, ...], bool], None] | None
    period_s: float
    fault_reason: str | None


class OnlineAttachment:
    """Owns the loop's online worker; ``wanted`` survives compensator changes.

    ``on_event(level, event, **fields)`` receives the worker's events (the daemon's log).
    ``handle_slip_deg`` and ``ripple_period_deg`` per knob come from the data sheet (None: the
    estimator's default), and so does the product's ``bend`` relation (None: the sheet has
    none).
    """

    def __init__(self, config: OnlineConfig, loop: Observed,
                 on_event: Callable[..., None] | None = None,
                 handle_slip_deg: tuple[float, float] | None = None,
                 bend: BendRelation | None = None,
                 ripple_period_deg: tuple[float | None, float | None] | None = None) -> None:
        self.config = config
        self.loop = loop
        self.on_event = on_event
        self.handle_slip_deg = handle_slip_deg
        self.ripple_period_deg = ripple_period_deg
        self.bend = bend
        self.wanted = config.enabled
        self.worker: OnlineWorker | None = None
        self._compensator: Any = None
        self._why_not = ""
        self._lock = threading.Lock()

    def attach(self, compensator: Any) -> None:
        """Replace the worker by one on ``compensator`` (call after the loop has it)."""
        with self._lock:
            self._detach()
            self._compensator = compensator
            if self.wanted:
                self._build()

    def detach(self) -> None:
        """Take the worker out of the loop and stop it (before a compensator is replaced)."""
        with self._lock:
            self._detach()

    def set_enabled(self, enabled: bool) -> dict[str, Any]:
        """Switch on (build or resume the worker) or off (the profile's values at once)."""
        with self._lock:
            if enabled and self.worker is None:
                self._build()
                if self.worker is None:
                    raise OnlineError(f"online: {self._why_not}")
            elif self.worker is not None:
                self.worker.set_enabled(enabled)
            self.wanted = enabled
            return self._status()

    def status(self) -> dict[str, Any]:
        with self._lock:
            return self._status()

    def save(self, profile: CatheterProfile | None, directory: Path) -> Path:
        """The estimates in force as a new profile version; never the calibrated file."""
        worker = self.worker
        if worker is None or not worker.enabled:
            raise OnlineError("online_save: online re-estimation is not running; "
                              "send online {\"enabled\": true} first")
        if profile is None:
            raise OnlineError("online_save: no catheter profile is loaded")
        return save_online_version(profile, worker.offsets(), directory,
                                   gains=worker.gains, zero_loads=worker.zero_loads,
                                   omega_per_gain=worker.omega_per_gain)

    def offsets_row(self) -> tuple[float, ...]:
        """The offsets in force, in :data:`tsmd.online.RECORDING_COLUMNS` order (0: none)."""
        worker = self.worker
        if worker is None:
            return (*ZERO_OFFSETS[0], *ZERO_OFFSETS[1])
        return worker.recording_values()

    def recording(self, recorder: TickRecorder) -> TickRecorder:
        """``recorder`` with the offsets in force appended to every row."""
        return _WithOffsets(recorder, self)

    def _fault_reason(self) -> str | None:
        """The loop's fault, read by the worker: a fault freezes the estimate with a warning."""
        return self.loop.fault_reason

    def _status(self) -> dict[str, Any]:
        if self.worker is None:
            out: dict[str, Any] = {"enabled": False}
            if self.wanted and self._why_not:
                out["reason"] = self._why_not
            return out
        return self.worker.status()

    def _build(self) -> None:
        c = self.config
        try:
            worker = OnlineWorker(
                self._compensator, self.loop.period_s, ROW_COLUMNS,
                estimator=EstimatorOptions(gate_deg=c.gate_deg, max_offset_deg=c.max_offset_deg,
                                           deadband_deg=c.deadband_deg),
                rate_deg_s=c.rate_deg_s, on_event=self.on_event,
                handle_slip_deg=self.handle_slip_deg, ripple_period_deg=self.ripple_period_deg,
                fault_reason=self._fault_reason,
                bend=self.bend)
        except OnlineError as exc:
            self._why_not = str(exc)
            if self.on_event is not None:
                self.on_event("warning", "online re-estimation unavailable", reason=str(exc))
            return
        self._why_not = ""
        worker.start()
        self.worker = worker
        self.loop.observer = worker.observe

    def _detach(self) -> None:
        worker, self.worker = self.worker, None
        self.loop.observer = None
        if worker is not None:
            worker.stop()


class _WithOffsets:
    """A tick recorder that appends the online offsets in force to each row."""

    def __init__(self, inner: TickRecorder, attachment: OnlineAttachment) -> None:
        self.inner = inner
        self.attachment = attachment

    def append(self, row: tuple[float, ...]) -> None:
        self.inner.append(row + self.attachment.offsets_row())
