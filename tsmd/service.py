"""The API's service object: what the handlers may ask of a running daemon besides the loop.

Status, switching compensation, loading a profile, calibrating on the live loop. The daemon's
life cycle (threads, signals, systemd notify) stays in :mod:`tsmd.daemon`.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tsmd import __version__, calibration
from tsmd.config import TsmdConfig, resolve_data_path
from tsmd.errors import TsmdError
from tsmd.loop import ControlLoop
from tsmd.profile import ProfileError, ProfileStore, load_device_model
from tsmd.rt import set_normal_scheduling
from tsmd.stack import StackError, knob_limits, make_compensator
from tsmd.trajectory import TrajectoryRunner


class ServiceError(TsmdError):
    """An API request could not be served; ``code`` is the API's error code."""

    def __init__(self, message: str, code: str = "service") -> None:
        super().__init__(message)
        self.code = code


@dataclass
class CompensationChoice:
    enabled: bool
    method: str

    @property
    def effective(self) -> str:
        return self.method if self.enabled else "none"


class Service:
    """What the API may do besides the loop: status, compensation, profiles, calibration.

    It knows nothing of the daemon's life cycle (threads, signals, systemd): the daemon builds
    it around a running loop and hands it to :class:`tsmd.api.handlers.ApiHandlers`.
    """

    def __init__(self, config: TsmdConfig, loop: ControlLoop, profile: Any,
                 choice: CompensationChoice, *, profiles_dir: Path,
                 on_event: Callable[..., None] | None = None,
                 runner_factory: Callable[[], TrajectoryRunner] | None = None,
                 extra_status: Callable[[], dict[str, Any]] | None = None) -> None:
        self.config = config
        self.loop = loop
        self.profile = profile
        self.choice = choice
        self.profiles_dir = profiles_dir
        self._on_event = on_event
        self._runner_factory = runner_factory
        self._extra_status = extra_status
        self._lock = threading.Lock()
        self.calibrating = False

    def _wait(self, name: str, **args: Any) -> Any:
        future = self.loop.post(name, **args)
        try:
            return future.result(timeout=15.0)
        except TimeoutError:
            raise ServiceError(f"{name}: the loop did not answer", "timeout") from None

    def status(self) -> dict[str, Any]:
        loop = self.loop
        sample = loop.latest_sample
        out: dict[str, Any] = {
            "version": __version__,
            "state": loop.state.value,
            "fault": loop.fault_reason,
            "rate_hz": 1.0 / loop.period_s,
            "ticks": loop.stats.ticks,
            "overruns": loop.stats.overruns,
            "faults": loop.stats.faults,
            "setpoint": list(q) if (q := loop.setpoint.get()) is not None else None,
            "compensation": {"enabled": self.choice.enabled, "method": self.choice.method,
                             "active": loop.compensation_label},
            "profile": getattr(self.profile, "catheter_id", None),
            "calibrating": self.calibrating,
            "sample": sample.as_dict() if sample is not None else None,
            "last_events": [f"drive {e.drive}: {e.kind.value}: {e.message}"
                            for e in list(loop.last_events)[-4:]],
        }
        if self._extra_status is not None:
            out.update(self._extra_status())
        return out

    def _activate(self, profile: Any, choice: CompensationChoice) -> None:
        try:
            compensator = make_compensator(profile, choice.effective, self.config)
        except StackError as exc:
            raise ServiceError(str(exc), exc.code) from None
        label = choice.effective if profile is not None else "none"
        self._wait("set_compensator", compensator=compensator, label=label)
        self.profile = profile
        self.choice = choice

    def set_compensation(self, enabled: bool | None, method: str | None) -> dict[str, Any]:
        with self._lock:
            choice = CompensationChoice(
                self.choice.enabled if enabled is None else enabled,
                self.choice.method if method is None else method)
            if choice.effective != "none" and self.profile is None:
                raise ServiceError("no catheter profile is loaded; send profile first",
                                  "no_profile")
            self._activate(self.profile, choice)
            return {"enabled": choice.enabled, "method": choice.method,
                    "active": self.loop.compensation_label}

    def load_profile(self, catheter: str | None) -> dict[str, Any]:
        if catheter is None:
            return {"profile": getattr(self.profile, "catheter_id", None),
                    "available": self._store().list()}
        with self._lock:
            try:
                profile = self._store().load(catheter)
            except ProfileError as exc:
                raise ServiceError(str(exc), "profile") from None
            self._activate(profile, self.choice)
            return {"profile": catheter, "active": self.loop.compensation_label}

    def _store(self) -> ProfileStore:
        return ProfileStore(self.profiles_dir)

    def calibrate(self, catheter: str, progress: Callable[[dict[str, Any]], None],
                  cancel: threading.Event) -> dict[str, Any]:
        """Run the calibration protocol on the live loop; save and activate the profile."""
        if self._runner_factory is None:
            raise ServiceError("calibration needs a running loop", "unavailable")
        device_path = self.config.profiles.device_model
        if device_path is None:
            raise ServiceError("profiles.device_model is not configured", "unavailable")
        try:
            device = load_device_model(resolve_data_path(device_path))
            knob_limits(self.config, device)  # the configured motion must fit the data sheet
        except ProfileError as exc:
            raise ServiceError(str(exc), "profile") from None
        except StackError as exc:
            raise ServiceError(str(exc), exc.code) from None
        if self.loop.state.value == "DISABLED":
            self._wait("enable")
        # This worker thread inherited SCHED_FIFO 1 (see Daemon): heavy identification work and
        # any process it starts must not starve the machine's ordinary processes.
        set_normal_scheduling()
        runner = self._runner_factory()

        def on_progress(fraction: float, line: str = "") -> None:
            progress({"progress": round(float(fraction), 4), "status": str(line),
                      "info": [str(line)]})

        self.calibrating = True
        try:
            profile = calibration.calibrate(runner, catheter, device, progress=on_progress,
                                            cancel=cancel)
        except calibration.CalibrationCancelledError as exc:
            raise ServiceError(f"calibration cancelled: {exc}", "cancelled") from None
        except calibration.CalibrationError as exc:
            raise ServiceError(f"calibration refused: {exc}", "calibration") from None
        finally:
            self.calibrating = False
        path = self._store().save(profile)
        with self._lock:
            self._activate(profile, self.choice)
        return {"profile": catheter, "path": str(path)}
