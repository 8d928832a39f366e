"""The API's service object: what the handlers may ask of a running daemon besides the loop.

Status, switching compensation, loading a profile, calibrating on the live loop. The daemon's
life cycle (threads, signals, systemd notify) stays in :mod:`tsmd.daemon`.
"""

from __future__ import annotations

import dataclasses
import threading
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from drivers.drive import DriveError, DriveUnreachableError, KnobDrives
from tsmd import __version__, calibration
from tsmd.config import TsmdConfig, resolve_data_path
from tsmd.errors import TsmdError
from tsmd.loop import ControlLoop, LoopError
from tsmd.online.apply import OnlineError
from tsmd.online.attach import OnlineAttachment
from tsmd.profile import ProfileError, ProfileStore, load_device_model
from tsmd.rt import set_normal_scheduling
from tsmd.stack import StackError, knob_limits, make_compensator, make_standby
from tsmd.trajectory import TrajectoryRunner


def _bus_state(drives: KnobDrives) -> str | None:
    """The CAN controller's state as the master last saw it (None: not a CAN backend)."""
    state = getattr(drives, "bus_state", None)
    return None if state is None else str(getattr(state, "value", state))


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
                 extra_status: Callable[[], dict[str, Any]] | None = None,
                 online: OnlineAttachment | None = None) -> None:
        self.config = config
        self.loop = loop
        self.profile = profile
        self.choice = choice
        self.profiles_dir = profiles_dir
        self._on_event = on_event
        self._runner_factory = runner_factory
        self._extra_status = extra_status
        self.online = online
        """The online re-estimation worker's owner (None: not offered by this daemon)."""
        self._lock = threading.Lock()
        self._calibration_lock = threading.Lock()
        self._calibration_cancel: threading.Event | None = None
        self._cancel_reason: str | None = None
        self.homing = False
        """True while a ``home`` command holds the loop thread (the daemon keeps feeding the
        systemd watchdog: the master bounds each homing by ``homing.timeout_s``)."""

    @property
    def calibrating(self) -> bool:
        """True from the moment a calibration is accepted until its thread has ended."""
        return self._calibration_cancel is not None

    def cancel_calibration(self, reason: str) -> bool:
        """Ask a running calibration to end (knobs back to 0, nothing saved); False if none."""
        cancel = self._calibration_cancel
        if cancel is None:
            return False
        if not cancel.is_set():
            self._cancel_reason = reason
            self._emit("warning", "calibration cancel requested", reason=reason)
        cancel.set()
        return True

    def _emit(self, level: str, event: str, **fields: Any) -> None:
        if self._on_event is not None:
            self._on_event(level, event, **fields)

    def _wait(self, name: str, timeout_s: float = 15.0, **args: Any) -> Any:
        future = self.loop.post(name, **args)
        try:
            return future.result(timeout=timeout_s)
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
            "homing": [dataclasses.asdict(h) for h in loop.drives.homing_status()],
            "zero_referenced": loop.drives.zero_referenced(),
            "bus_state": _bus_state(loop.drives),
            "sample": sample.as_dict() if sample is not None else None,
            "last_events": [f"drive {e.drive}: {e.kind.value}: {e.message}"
                            for e in list(loop.last_events)[-4:]],
            "online": self.online.status() if self.online is not None else {"enabled": False},
        }
        if self._extra_status is not None:
            out.update(self._extra_status())
        return out

    def sample(self) -> dict[str, Any] | None:
        """The latest tick for ``get``/``subscribe``, with the online offsets in force
        (``online_offsets_deg`` [[phi1 pos, neg], [phi2 pos, neg]], null while online is off)."""
        sample = self.loop.latest_sample
        if sample is None:
            return None
        out = sample.as_dict()
        online = self.online
        worker = online.worker if online is not None else None
        if worker is not None and worker.enabled:
            off = worker.offsets()
            out["online_offsets_deg"] = [list(off[0]), list(off[1])]
        else:
            out["online_offsets_deg"] = None
        return out

    def require_zero_reference(self, what: str) -> None:
        """Refuse motion while the config requires homing and a knob has no zero reference."""
        drives = self.loop.drives
        if drives.zero_referenced():
            return
        missing = [i for i, h in enumerate(drives.homing_status()) if h.required and not h.homed]
        raise ServiceError(f"{what}: drive(s) {', '.join(map(str, missing))} have no zero "
                           "reference (homing required by the config); send home first",
                           "not_homed")

    def home(self, drives: list[int] | None) -> dict[str, Any]:
        """Run the configured homing of the chosen drives (all by default) between two ticks."""
        status = self.loop.drives.homing_status()
        if drives is not None:
            for i in drives:
                if not 0 <= i < len(status):
                    raise ServiceError(f"home: no drive {i} (drives 0..{len(status) - 1})",
                                       "bad_param")
        chosen = range(len(status)) if drives is None else drives
        with self._calibration_lock:  # one motion owner at a time: homing or calibration
            if self.calibrating or self.homing:
                raise ServiceError("home: a calibration or a homing is running", "busy")
            self.homing = True
        self._emit("info", "homing started", drives=list(chosen))
        try:
            self._wait("home", timeout_s=self._homing_budget_s(list(chosen)), drives=drives)
        except LoopError as exc:
            raise ServiceError(f"home: {exc}", exc.code) from None
        except DriveError as exc:
            self._emit("error", "homing failed", reason=str(exc))
            code = "fault" if isinstance(exc, DriveUnreachableError) else "homing"
            raise ServiceError(f"home: {exc}", code) from None
        finally:
            self.homing = False
        result = [dataclasses.asdict(h) for h in self.loop.drives.homing_status()]
        self._emit("info", "homing finished", homing=result)
        return {"homing": result, "zero_referenced": self.loop.drives.zero_referenced()}

    def _homing_budget_s(self, drives: list[int]) -> float:
        """How long a homing may hold the loop: each drive's own timeout, plus the walk."""
        configs = getattr(self.loop.drives, "configs", None)
        if configs is None:
            return 15.0
        return 15.0 + sum(configs[i].homing.timeout_s for i in drives if i < len(configs))

    def _activate(self, profile: Any, choice: CompensationChoice) -> None:
        try:
            compensator = make_compensator(profile, choice.effective, self.config)
        except StackError as exc:
            raise ServiceError(str(exc), exc.code) from None
        label = choice.effective if profile is not None else "none"
        # the same catheter: each new compensator continues from the one of its method that
        # was active or followed the motor (switching on mid-motion keeps the branch)
        self._wait("set_compensator", compensator=compensator, label=label,
                   standby=make_standby(profile, choice.method, label, self.config),
                   keep_state=profile is self.profile)
        self.profile = profile
        self.choice = choice
        if self.online is not None:  # a new worker, on the new compensator's own values
            self.online.attach(compensator)

    def set_online(self, enabled: bool | None) -> dict[str, Any]:
        """Switch online re-estimation; off puts the profile's values back at once."""
        online = self._online("online")
        if enabled is None:
            return online.status()
        with self._lock:
            try:
                return online.set_enabled(enabled)
            except OnlineError as exc:
                raise ServiceError(str(exc), "online") from None

    def save_online(self) -> dict[str, Any]:
        """Save the online estimates as a new profile version next to the calibrated one."""
        online = self._online("online_save")
        with self._lock:
            try:
                path = online.save(self.profile, self.profiles_dir)
            except OnlineError as exc:
                raise ServiceError(str(exc), "online") from None
            except OSError as exc:
                raise ServiceError(f"online_save: cannot write to {self.profiles_dir}: "
                                   f"{exc.strerror or exc}", "online") from None
        self._emit("info", "online estimates saved", path=str(path))
        return {"path": str(path), "profile": getattr(self.profile, "catheter_id", None)}

    def _online(self, what: str) -> OnlineAttachment:
        if self.online is None:
            raise ServiceError(f"{what}: online re-estimation is not available here",
                               "unavailable")
        return self.online

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
            except (ValueError, TypeError, LookupError, RecursionError) as exc:
                # a defect the reader missed: name it, never echo the file's bytes
                raise ServiceError(f"profile {catheter!r}: the file is not a valid profile "
                                   f"({type(exc).__name__})", "profile") from None
            self._activate(profile, self.choice)
            return {"profile": catheter, "active": self.loop.compensation_label}

    def _store(self) -> ProfileStore:
        return ProfileStore(self.profiles_dir)

    def calibrate(self, catheter: str, progress: Callable[[dict[str, Any]], None],
                  cancel: threading.Event) -> dict[str, Any]:
        """Run the calibration protocol on the live loop; save and activate the profile.

        One at a time: a second request while one runs is refused (``busy``). ``cancel`` (set by
        :meth:`cancel_calibration`, a ``stop``, a shutdown or the client's disconnection) ends it
        with the knobs back at 0 and nothing saved.
        """
        with self._calibration_lock:
            if self._calibration_cancel is not None or self.homing:
                raise ServiceError("calibrate: a calibration or a homing is already running",
                                   "busy")
            self._calibration_cancel = cancel
            self._cancel_reason = None
        try:
            return self._calibrate(catheter, progress, cancel)
        finally:
            self._calibration_cancel = None

    def _calibrate(self, catheter: str, progress: Callable[[dict[str, Any]], None],
                   cancel: threading.Event) -> dict[str, Any]:
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
        self.require_zero_reference("calibrate")
        if self.loop.state.value == "DISABLED":
            self._wait("enable")
        # This worker thread inherited SCHED_FIFO 1 (see Daemon): heavy identification work and
        # any process it starts must not starve the machine's ordinary processes.
        set_normal_scheduling()
        runner = self._runner_factory()

        def on_progress(fraction: float, line: str = "") -> None:
            progress({"progress": round(float(fraction), 4), "status": str(line),
                      "info": [str(line)]})

        self._emit("info", "calibration started", catheter=catheter)
        try:
            profile = calibration.calibrate(runner, catheter, device, progress=on_progress,
                                            cancel=cancel)
        except TsmdError as exc:
            # After a cancel, whatever ended the protocol (a stop or a shutdown disabling the
            # loop under it) is the cancel's doing: say so, not the symptom.
            if cancel.is_set() or isinstance(exc, calibration.CalibrationCancelledError):
                reason = self._cancel_reason or "its client disconnected"
                if isinstance(exc, calibration.CalibrationCancelledError):
                    detail = str(exc)
                else:  # the loop was stopped under it: the knobs stay where the stop left them
                    detail = "the drives were stopped; nothing saved"
                self._emit("warning", "calibration cancelled", catheter=catheter, reason=reason,
                           detail=detail)
                raise ServiceError(f"calibration cancelled ({reason}): {detail}",
                                   "cancelled") from None
            self._emit("error", "calibration failed", catheter=catheter, reason=str(exc))
            if isinstance(exc, calibration.CalibrationError):
                raise ServiceError(f"calibration refused: {exc}", "calibration") from None
            raise ServiceError(f"calibration failed: {exc}", "calibration") from None
        path = self._store().save(profile)
        with self._lock:
            self._activate(profile, self.choice)
        self._emit("info", "calibration finished", catheter=catheter, path=str(path))
        return {"profile": catheter, "path": str(path)}
