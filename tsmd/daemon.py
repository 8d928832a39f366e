"""The daemon: drives + profile + compensator + loop thread + API thread, started and stopped
in the safe order.

Start: open and boot the drives, load the active profile, build the compensator, start the
loop thread (real-time settings applied inside it), bind the API socket, tell systemd READY.
Stop (SIGTERM, SIGINT, the end of ``--duration``): quick stop and disable the drives from the
loop thread, stop the loop, flush the recording, close the socket and the bus.
"""

from __future__ import annotations

import contextlib
import gc
import importlib
import os
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from drivers.clock import MonotonicClock
from drivers.drive import DriveError, KnobDrives
from tsmd import __version__
from tsmd.api.handlers import ApiHandlers
from tsmd.api.server import ApiServer
from tsmd.config import TsmdConfig, drive_configs
from tsmd.errors import TsmdError
from tsmd.log import EventLog, get_logger
from tsmd.loop import BackgroundRecorder, ControlLoop, KnobLimiter, KnobRange, LoopError
from tsmd.notify import Notifier, watchdog_interval_s
from tsmd.rt import (
    FixedRateScheduler,
    RealtimeReport,
    apply_realtime,
    set_fifo,
    set_normal_scheduling,
)

PACKAGE_ROOT = Path(__file__).resolve().parent.parent
SIM_EXAMPLE_PROFILE = "profiles/example-sim.yaml"


class DaemonError(TsmdError):
    """The daemon could not start (drives, profile, socket); the message says which and why."""

    def __init__(self, message: str, code: str = "daemon") -> None:
        super().__init__(message)
        self.code = code


def resolve_socket_path(configured: str, explicit: str | None = None) -> tuple[Path, str | None]:
    """Where to listen, and a warning when the configured place cannot be used.

    An explicit path wins; under systemd ``$RUNTIME_DIRECTORY`` (RuntimeDirectory=) holds the
    socket; otherwise the configured path, or, when its directory cannot be created or written
    (a non-root user without /run/tsmd), a per-user runtime directory.
    """
    if explicit:
        return Path(explicit), None
    runtime = os.environ.get("RUNTIME_DIRECTORY")
    name = Path(configured).name or "tsmd.sock"
    if runtime:
        return Path(runtime.split(":")[0]) / name, None
    path = Path(configured)
    parent = path.parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        usable = os.access(parent, os.W_OK | os.X_OK)
    except OSError:
        usable = False
    if usable:
        return path, None
    base = os.environ.get("XDG_RUNTIME_DIR") or tempfile.gettempdir()
    fallback = Path(base) / f"tsmd-{os.getuid()}" / name
    return fallback, f"cannot use {parent} for the socket; listening on {fallback} instead"


def resolve_data_path(path: str) -> Path:
    """Relative paths: the working directory first, then the source tree (profiles/...)."""
    p = Path(path)
    if p.is_absolute() or p.exists():
        return p
    candidate = PACKAGE_ROOT / p
    return candidate if candidate.exists() else p


def knob_limits(config: TsmdConfig) -> tuple[Any, Any]:
    from tsmd.compensation.safety import KnobLimits

    return tuple(KnobLimits(k.min_deg, k.max_deg, k.max_velocity_deg_s, k.max_accel_deg_s2)
                 for k in config.limits.knobs())  # type: ignore[return-value]


def make_compensator(profile: Any, method: str, config: TsmdConfig) -> Any:
    """The compensator for ``profile`` (None: no compensation), pure and cheap to build.

    It knows the configured motor limits (when a jump across a dead zone must start) but does
    not apply them: the loop applies the rate/position limiter itself, last.
    """
    from tsmd.compensation import build_compensator

    if profile is None:
        method = "none"
    try:
        return build_compensator(profile, method, config.loop.period_s,
                                 knob_limits(config), apply_limits=False)
    except (ValueError, TsmdError) as exc:
        raise DaemonError(f"cannot build the {method!r} compensator for "
                          f"{getattr(profile, 'catheter_id', '?')}: {exc}",
                          "compensation") from None


@dataclass
class CompensationChoice:
    enabled: bool
    method: str

    @property
    def effective(self) -> str:
        return self.method if self.enabled else "none"


class Controller:
    """What the API may do besides the loop: status, compensation, profiles, calibration."""

    def __init__(self, config: TsmdConfig, loop: ControlLoop, profile: Any,
                 choice: CompensationChoice, *, profiles_dir: Path,
                 on_event: Callable[..., None] | None = None,
                 runner_factory: Callable[[], Any] | None = None,
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
            raise DaemonError(f"{name}: the loop did not answer", "timeout") from None

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
        compensator = make_compensator(profile, choice.effective, self.config)
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
                raise DaemonError("no catheter profile is loaded; send profile first",
                                  "no_profile")
            self._activate(self.profile, choice)
            return {"enabled": choice.enabled, "method": choice.method,
                    "active": self.loop.compensation_label}

    def load_profile(self, catheter: str | None) -> dict[str, Any]:
        if catheter is None:
            return {"profile": getattr(self.profile, "catheter_id", None),
                    "available": self._store().list()}
        from tsmd.profile import ProfileError

        with self._lock:
            try:
                profile = self._store().load(catheter)
            except ProfileError as exc:
                raise DaemonError(str(exc), "profile") from None
            self._activate(profile, self.choice)
            return {"profile": catheter, "active": self.loop.compensation_label}

    def _store(self) -> Any:
        from tsmd.profile import ProfileStore

        return ProfileStore(self.profiles_dir)

    def calibrate(self, catheter: str, progress: Callable[[dict[str, Any]], None],
                  cancel: threading.Event) -> dict[str, Any]:
        """Run the calibration protocol on the live loop; save and activate the profile."""
        try:
            calibration = importlib.import_module("tsmd.calibration")
        except ImportError:
            raise DaemonError("calibration is not available in this build",
                              "unavailable") from None
        if self._runner_factory is None:
            raise DaemonError("calibration needs a running loop", "unavailable")
        device_path = self.config.profiles.device_model
        if device_path is None:
            raise DaemonError("profiles.device_model is not configured", "unavailable")
        from tsmd.profile import ProfileError, load_device_model

        try:
            device = load_device_model(resolve_data_path(device_path))
        except ProfileError as exc:
            raise DaemonError(str(exc), "profile") from None
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
            profile = calibration.calibrate(runner, catheter, device,
                                            period_s=self.loop.period_s,
                                            progress=on_progress, cancel=cancel)
        except calibration.CalibrationCancelledError as exc:
            raise DaemonError(f"calibration cancelled: {exc}", "cancelled") from None
        except calibration.CalibrationError as exc:
            raise DaemonError(f"calibration refused: {exc}", "calibration") from None
        finally:
            self.calibrating = False
        path = self._store().save(profile)
        with self._lock:
            self._activate(profile, self.choice)
        return {"profile": catheter, "path": str(path)}


@dataclass
class RunSummary:
    ticks: int
    overruns: int
    faults: int
    lateness_p99_ms: float
    lateness_max_ms: float
    state: str
    fault: str | None


class Daemon:
    """Owns every part; :meth:`start`, then :meth:`wait`, then :meth:`stop` (idempotent)."""

    def __init__(self, config: TsmdConfig, *, sim: bool = False, socket_path: str | None = None,
                 profile_path: str | None = None, api: bool = True) -> None:
        self.config = config
        self.sim = sim
        self.api = api
        self.log = get_logger("tsmd")
        self._helper_rt_warning: str | None = None
        if config.loop.realtime.priority > 1:
            # Every thread created from here on (log, API, recorder, simulated rig) inherits
            # SCHED_FIFO 1: a thread holding the GIL is then never descheduled by ordinary
            # processes while the loop thread (priority above) waits for the GIL.
            self._helper_rt_warning = set_fifo(1)
        self.events = EventLog(self.log)
        self._socket_override = socket_path
        self._profile_path = profile_path
        self.drives: KnobDrives | None = None
        self.rig: Any = None
        self.loop: ControlLoop | None = None
        self.controller: Controller | None = None
        self.server: ApiServer | None = None
        self.scheduler: FixedRateScheduler | None = None
        self.recorder: BackgroundRecorder | None = None
        self.socket_path: Path | None = None
        self.notifier = Notifier()
        self.rt_report: RealtimeReport | None = None
        self._loop_stop = threading.Event()
        self._loop_thread: threading.Thread | None = None
        self._loop_error: BaseException | None = None
        self._stopped = False
        self._can_writer: Any = None
        self.shutdown_requested = threading.Event()

    # --- start -----------------------------------------------------------------------------

    def start(self) -> None:
        config = self.config
        # The loop thread must get the GIL within a fraction of a period, not the default 5 ms.
        sys.setswitchinterval(min(sys.getswitchinterval(), config.loop.period_s / 10))
        try:
            profile = self._load_profile()
            compensator = self._build_compensator(profile)
            gc.collect()  # the one full collection, before any thread that must be punctual
            self._open_drives()  # from boot on, the drives expect SYNC + heartbeat: no delay
            self._build_loop(profile, compensator)
            self._start_loop_thread()
            if self.api:
                self._start_api()
        except BaseException:
            self.stop()
            raise
        # Everything built so far lives as long as the daemon: keep it out of the cyclic
        # garbage collector, whose full passes over it would stall a tick for milliseconds.
        # (No collect() here: it holds the GIL for ~100 ms while the loop already ticks.)
        gc.freeze()
        self.notifier.ready(status=f"tsmd ready: {config.loop.rate_hz:g} Hz, socket "
                                   f"{self.socket_path}")
        self.log.info("ready", socket=str(self.socket_path), rate_hz=config.loop.rate_hz,
                      sim=self.sim, profile=getattr(profile, "catheter_id", None),
                      compensation=self.loop.compensation_label if self.loop else None)

    def _open_drives(self) -> None:
        config = self.config
        drive_cfgs = drive_configs(config)
        if self.sim:
            from simrig.plant import load_plant
            from simrig.rig import open_sim_rig

            plant = load_plant(config.sim.plant, config.sim.params)
            self.drives, self.rig = open_sim_rig(plant, drive_cfgs, config.loop.period_s,
                                                 config.sim.seed, lockstep=False,
                                                 receive="poll")
            from tsmd.replay import configure_tracker

            configure_tracker(self.rig, config.sim.tracker_noise_deg, config.sim.seed)
        else:
            self.drives = self._open_bus_drives(drive_cfgs)
        try:
            self.drives.boot()
        except DriveError as exc:
            raise DaemonError(f"drive boot failed: {exc}", "drive") from None
        self.log.info("drives booted", count=self.drives.count)

    def _open_bus_drives(self, drive_cfgs: list[Any]) -> KnobDrives:
        """The master on the configured bus; the loop thread polls it every tick.

        Polling (no python-can notifier thread) leaves one thread touching the bus and one
        fewer thread competing with the loop for the GIL.
        """
        import can

        from drivers.canopen_master import CanOpenDrives

        bus_cfg = self.config.bus
        kwargs: dict[str, Any] = {}
        if bus_cfg.interface == "udp_multicast":  # it echoes our own frames: accept only theirs
            kwargs["can_filters"] = [{"can_id": base + c.node_id, "can_mask": 0x7FF}
                                     for c in drive_cfgs for base in (0x080, 0x180, 0x580, 0x700)]
        try:
            bus = can.Bus(interface=bus_cfg.interface, channel=bus_cfg.channel,
                          bitrate=bus_cfg.bitrate, **kwargs)
        except (can.CanError, OSError, ValueError, ImportError) as exc:
            raise DaemonError(f"cannot open CAN interface {bus_cfg.interface!r} channel "
                              f"{bus_cfg.channel!r}: {exc}", "drive") from None
        self._can_log(bus)
        return CanOpenDrives(bus, drive_cfgs, self.config.loop.period_s, receive="poll",
                             own_bus=True)

    def _can_log(self, bus: Any) -> None:
        """bus.log_format: every frame sent and received, in python-can's BLF or ASC writer."""
        fmt = self.config.bus.log_format
        if fmt == "none":
            return
        import can

        directory = resolve_data_path(self.config.recording.dir)
        directory.mkdir(parents=True, exist_ok=True)
        stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
        path = directory / f"tsmd-can-{stamp}.{fmt}"
        writer = can.Logger(str(path))
        self._can_writer = writer
        recv, send = bus.recv, bus.send

        def logged_recv(timeout: float | None = None) -> Any:
            msg = recv(timeout)
            if msg is not None:
                writer.on_message_received(msg)
            return msg

        def logged_send(msg: Any, timeout: float | None = None) -> None:
            send(msg, timeout)
            writer.on_message_received(msg)

        bus.recv, bus.send = logged_recv, logged_send
        self.log.info("logging CAN traffic", path=str(path), format=fmt)

    def _load_profile(self) -> Any:
        from tsmd.profile import ProfileError, ProfileStore, load_profile

        config = self.config
        try:
            if self._profile_path is not None:
                return load_profile(self._profile_path)
            if config.profiles.active is None:
                example = resolve_data_path(SIM_EXAMPLE_PROFILE)
                if self.sim and example.exists():  # the simulated catheter's own profile
                    self.log.info("no profile configured: using the simulated catheter's",
                                  path=str(example))
                    return load_profile(example)
                return None
            return ProfileStore(resolve_data_path(config.profiles.dir)).load(
                config.profiles.active)
        except ProfileError as exc:
            raise DaemonError(f"cannot load the active profile: {exc}", "profile") from None

    def _build_compensator(self, profile: Any) -> Any:
        config = self.config
        choice = CompensationChoice(config.compensation.enabled, config.compensation.method)
        if profile is None and choice.effective != "none":
            self.log.warning("no catheter profile: compensation off until one is loaded")
        return make_compensator(profile, choice.effective, config)

    def _build_loop(self, profile: Any, compensator: Any) -> None:
        config = self.config
        assert self.drives is not None
        choice = CompensationChoice(config.compensation.enabled, config.compensation.method)
        label = choice.effective if profile is not None else "none"
        if config.recording.enabled:
            directory = resolve_data_path(config.recording.dir)
            directory.mkdir(parents=True, exist_ok=True)
            stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
            self.recorder = BackgroundRecorder(
                str(directory / f"tsmd-{stamp}.csv"),
                {"source": "tsmd run", "version": __version__, "rate_hz": config.loop.rate_hz,
                 "profile": getattr(profile, "catheter_id", "none"), "compensation": label,
                 "sim": self.sim}, config.recording.flush_interval_s)
        tip_source = self.rig.tip_deg if self.rig is not None else None
        self.loop = ControlLoop(
            self.drives, compensator, KnobLimiter(knob_limits(config), config.loop.period_s),
            [KnobRange(k.min_deg, k.max_deg) for k in config.limits.knobs()],
            config.loop.period_s, MonotonicClock(),
            stale_feedback_syncs=config.loop.stale_feedback_syncs,
            overrun_fault_streak=config.loop.overrun_fault_streak,
            compensation_label=label, tip_source=tip_source, recorder=self.recorder,
            on_event=self.events.emit)
        self.controller = Controller(
            config, self.loop, profile, choice,
            profiles_dir=resolve_data_path(config.profiles.dir), on_event=self.events.emit,
            runner_factory=self._live_runner, extra_status=self._extra_status)

    def _live_runner(self) -> Any:
        from tsmd.replay import LiveTrajectoryRunner

        assert self.loop is not None
        return LiveTrajectoryRunner(self.loop)

    def _extra_status(self) -> dict[str, Any]:
        out: dict[str, Any] = {"sim": self.sim}
        if self.server is not None:
            out["clients"] = self.server.client_count
        if self.rt_report is not None:
            out["realtime"] = {"fifo_priority": self.rt_report.fifo_priority,
                               "cpu": self.rt_report.cpu,
                               "memory_locked": self.rt_report.memory_locked}
        return out

    def _start_loop_thread(self) -> None:
        loop = self.loop
        assert loop is not None

        def on_tick_end(overran: bool) -> None:
            loop.note_overrun(overran)

        def reanchor() -> bool:
            if loop.schedule_reset:
                loop.schedule_reset = False
                return True
            return False

        self.scheduler = FixedRateScheduler(loop.period_s, loop.tick, on_tick_end=on_tick_end,
                                            should_reanchor=reanchor)
        started = threading.Event()
        rt = self.config.loop.realtime

        def run() -> None:
            self.rt_report = apply_realtime(rt.priority, rt.cpu, rt.lock_memory)
            started.set()
            try:
                assert self.scheduler is not None
                self.scheduler.run(self._loop_stop)
            except BaseException as exc:  # the loop died: make it visible, then stop
                self._loop_error = exc
                self.events.emit("critical", "loop thread died", error=repr(exc))
                with contextlib.suppress(DriveError):
                    loop.drives.quick_stop()
                self.shutdown_requested.set()

        self._loop_thread = threading.Thread(target=run, name="tsmd-loop", daemon=True)
        self._loop_thread.start()
        started.wait(5.0)
        deadline = time.monotonic() + 5.0
        while loop.latest_sample is None and time.monotonic() < deadline:
            time.sleep(loop.period_s)  # READY means the loop is ticking
        if loop.latest_sample is None:
            raise DaemonError("the control loop did not start ticking", "loop")
        if self._helper_rt_warning is not None:
            self.log.warning("real-time setting not applied",
                             reason=f"helper threads: {self._helper_rt_warning}")
        for warning in self.rt_report.warnings if self.rt_report else []:
            self.log.warning("real-time setting not applied", reason=warning)

    def _start_api(self) -> None:
        config = self.config
        assert self.controller is not None
        path, warning = resolve_socket_path(config.api.socket_path, self._socket_override)
        if warning is not None:
            self.log.warning("socket fallback", reason=warning)
        handlers = ApiHandlers(self.controller, max_subscribe_hz=config.api.max_subscribe_hz)
        self.server = ApiServer(path, handlers, mode=config.api.socket_mode,
                                max_line_bytes=config.api.max_line_bytes,
                                max_clients=config.api.max_clients, on_event=self.events.emit,
                                loop_cpu=config.loop.realtime.cpu)
        self.server.start()
        self.socket_path = path

    # --- run and stop ----------------------------------------------------------------------

    def wait(self, duration_s: float | None = None) -> None:
        """Block until the duration has passed or a shutdown was requested; feeds systemd."""
        deadline = None if duration_s is None else time.monotonic() + duration_s
        interval = watchdog_interval_s()
        tick = min(interval, 1.0) if interval else 1.0
        last_ticks = -1
        while not self.shutdown_requested.is_set():
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0:
                break
            self.shutdown_requested.wait(tick if remaining is None else min(tick, remaining))
            loop = self.loop
            if loop is None:
                continue
            if loop.stats.ticks != last_ticks:  # the loop is alive: feed the watchdog
                self.notifier.watchdog()
                last_ticks = loop.stats.ticks
            self.notifier.status(f"{loop.state.value}; ticks {loop.stats.ticks}; overruns "
                                 f"{loop.stats.overruns}; {loop.compensation_label}")

    def stop(self) -> RunSummary | None:
        """Quick stop, disable, stop the loop, flush the recording, close everything."""
        if self._stopped:
            return None
        self._stopped = True
        self.notifier.stopping()
        loop = self.loop
        if loop is not None and self._loop_thread is not None and self._loop_thread.is_alive():
            try:
                loop.post("shutdown").result(timeout=5.0)
            except (LoopError, DriveError, TimeoutError) as exc:
                self.log.error("shutdown command failed", reason=str(exc))
        self._loop_stop.set()
        if self._loop_thread is not None:
            self._loop_thread.join(5.0)
        if self.server is not None:
            self.server.stop()
        if self.recorder is not None:
            self.recorder.close()
            self.log.info("recording written", path=self.recorder.path,
                          rows=self.recorder.rows_written)
        if self.drives is not None:
            with contextlib.suppress(DriveError):
                self.drives.close()
        if self.rig is not None and hasattr(self.rig, "close"):
            self.rig.close()
        if self._can_writer is not None:
            self._can_writer.stop()
        summary = self.summary()
        self.events.close()
        self.notifier.close()
        return summary

    @property
    def loop_error(self) -> BaseException | None:
        """What killed the loop thread, if it died (the process then exits non-zero)."""
        return self._loop_error

    def summary(self) -> RunSummary | None:
        loop = self.loop
        if loop is None:
            return None
        late = self.scheduler.times.lateness() if self.scheduler is not None else np.zeros(0)
        return RunSummary(
            ticks=loop.stats.ticks, overruns=loop.stats.overruns, faults=loop.stats.faults,
            lateness_p99_ms=float(np.percentile(late, 99) * 1e3) if late.size else 0.0,
            lateness_max_ms=float(late.max() * 1e3) if late.size else 0.0,
            state=loop.state.value, fault=loop.fault_reason)
