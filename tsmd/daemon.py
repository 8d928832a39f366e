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
import os
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from drivers.clock import MonotonicClock
from drivers.drive import DriveError, KnobDrives
from simrig.rig import SimRig
from tsmd import __version__, daemon_drives
from tsmd.api.handlers import ApiHandlers
from tsmd.api.server import ApiServer
from tsmd.bus_events import BusEventLog
from tsmd.compensation import Compensator
from tsmd.config import TsmdConfig, drive_configs, resolve_data_path
from tsmd.daemon_loop import LoopThread, RunSummary
from tsmd.errors import DaemonError
from tsmd.log import EventLog, get_logger
from tsmd.loop import BackgroundRecorder, ControlLoop, LoopError
from tsmd.notify import Notifier, watchdog_interval_s
from tsmd.online import RECORDING_COLUMNS
from tsmd.online.attach import OnlineAttachment
from tsmd.online.bend import sheet_bend_relation
from tsmd.profile import (
    CatheterProfile,
    DeviceModel,
    ProfileError,
    ProfileStore,
    load_device_model,
    load_profile,
)
from tsmd.replay import LiveTrajectoryRunner
from tsmd.rt import FixedRateScheduler, RealtimeReport, set_fifo
from tsmd.service import CompensationChoice, Service
from tsmd.stack import StackError, build_loop, make_compensator, make_standby, open_sim

SIM_EXAMPLE_PROFILE = "profiles/example-sim.yaml"


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


class Daemon:
    """Owns every part; :meth:`start`, then :meth:`wait`, then :meth:`stop` (idempotent)."""

    def __init__(self, config: TsmdConfig, *, sim: bool = False, socket_path: str | None = None,
                 profile_path: str | None = None, api: bool = True,
                 home_at_start: bool = False) -> None:
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
        self._bus_log = BusEventLog(self.events)
        self._socket_override = socket_path
        self._profile_path = profile_path
        self._home_all = home_at_start
        """``tsmd run --home``: home every drive that has a method, at start."""
        self.drives: KnobDrives | None = None
        self.rig: SimRig | None = None
        self.loop: ControlLoop | None = None
        self.service: Service | None = None
        self.online: OnlineAttachment | None = None
        self.server: ApiServer | None = None
        self.recorder: BackgroundRecorder | None = None
        self.socket_path: Path | None = None
        self.notifier = Notifier()
        self.loop_thread: LoopThread | None = None
        self._stopped = False
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
            self.drives, self.rig = open_sim(config, config.sim.seed, lockstep=False,
                                             receive="poll",
                                             timeouts=config.bus.timeouts.master())
        else:
            self.drives = daemon_drives.open_bus_drives(config, drive_cfgs, self.log)
        try:
            self.drives.boot()
        except DriveError as exc:
            raise DaemonError(f"drive boot failed: {exc}", "drive") from None
        self.log.info("drives booted", count=self.drives.count)
        daemon_drives.home_at_start(self.drives, drive_cfgs, self._home_all, self.log)

    def _load_profile(self) -> CatheterProfile | None:
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

    def _build_compensator(self, profile: CatheterProfile | None) -> Compensator:
        config = self.config
        choice = CompensationChoice(config.compensation.enabled, config.compensation.method)
        if profile is None and choice.effective != "none":
            self.log.warning("no catheter profile: compensation off until one is loaded")
        try:
            return make_compensator(profile, choice.effective, config)
        except StackError as exc:
            raise DaemonError(str(exc), exc.code) from None

    def _build_loop(self, profile: CatheterProfile | None, compensator: Compensator) -> None:
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
                 "sim": self.sim}, config.recording.flush_interval_s,
                # the file's columns are fixed at its start: online offsets only if on by config
                RECORDING_COLUMNS if config.online.enabled else ())
        tip_source = self.rig.tip_pair if self.rig is not None else None
        self.loop = build_loop(config, self.drives, compensator, MonotonicClock(),
                               compensation_label=label, tip_source=tip_source,
                               recorder=self.recorder, on_event=self.events.emit,
                               standby=make_standby(profile, choice.method, label, config))
        sheet = self._online_sheet(config)
        self.online = OnlineAttachment(
            config.online, self.loop, on_event=self.events.emit,
            handle_slip_deg=None if sheet is None else (sheet.knobs[0].handle_slip_deg,
                                                        sheet.knobs[1].handle_slip_deg),
            bend=sheet_bend_relation(sheet),
            ripple_period_deg=None if sheet is None else (
                sheet.knobs[0].torque_ripple_period_deg, sheet.knobs[1].torque_ripple_period_deg))
        if self.recorder is not None and config.online.enabled:
            self.loop.recorder = self.online.recording(self.recorder)
        self.online.attach(compensator)
        self.service = Service(
            config, self.loop, profile, choice,
            profiles_dir=resolve_data_path(config.profiles.dir), on_event=self.events.emit,
            runner_factory=self._live_runner, extra_status=self._extra_status,
            online=self.online)

    def _online_sheet(self, config: TsmdConfig) -> DeviceModel | None:
        """The data sheet online re-estimation reads its handle slip per knob and the
        product's bend relation from (None: the estimator's defaults, no relation)."""
        path = config.profiles.device_model
        if path is None:
            return None
        try:
            return load_device_model(resolve_data_path(path))
        except ProfileError as exc:
            self.events.emit("warning", "online: data sheet unreadable, default handle slip "
                             "and no bend relation", reason=str(exc))
            return None

    def _live_runner(self) -> LiveTrajectoryRunner:
        assert self.loop is not None
        return LiveTrajectoryRunner(self.loop)

    def _extra_status(self) -> dict[str, Any]:
        out: dict[str, Any] = {"sim": self.sim}
        if self.server is not None:
            out["clients"] = self.server.client_count
        report = self.rt_report
        if report is not None:
            out["realtime"] = {"fifo_priority": report.fifo_priority, "cpu": report.cpu,
                               "memory_locked": report.memory_locked}
        return out

    def _start_loop_thread(self) -> None:
        assert self.loop is not None

        def on_death(exc: BaseException) -> None:
            self.events.emit("critical", "loop thread died", error=repr(exc))
            self.shutdown_requested.set()

        self.loop_thread = LoopThread(self.loop, self.config.loop.realtime, on_death)
        self.loop_thread.start()
        if self._helper_rt_warning is not None:
            self.log.warning("real-time setting not applied",
                             reason=f"helper threads: {self._helper_rt_warning}")
        report = self.loop_thread.rt_report
        for warning in report.warnings if report else []:
            self.log.warning("real-time setting not applied", reason=warning)

    def _start_api(self) -> None:
        config = self.config
        assert self.service is not None
        path, warning = resolve_socket_path(config.api.socket_path, self._socket_override)
        if warning is not None:
            self.log.warning("socket fallback", reason=warning)
        handlers = ApiHandlers(self.service, max_subscribe_hz=config.api.max_subscribe_hz)
        self.server = ApiServer(path, handlers, mode=config.api.socket_mode,
                                max_line_bytes=config.api.max_line_bytes,
                                max_clients=config.api.max_clients,
                                idle_timeout_s=config.api.idle_timeout_s,
                                partial_line_timeout_s=config.api.partial_line_timeout_s,
                                accepts_per_s=config.api.accepts_per_s, on_event=self.events.emit,
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
            self.log_bus_events()
            loop = self.loop
            if loop is None:
                continue
            homing = self.service is not None and self.service.homing
            if loop.stats.ticks != last_ticks or homing:  # alive (a homing holds the loop
                self.notifier.watchdog()                  # thread, bounded by its timeout_s)
                last_ticks = loop.stats.ticks
            self.notifier.status(f"{loop.state.value}; ticks {loop.stats.ticks}; overruns "
                                 f"{loop.stats.overruns}; {loop.compensation_label}")

    def log_bus_events(self) -> int:
        """Log the CAN bus events decoded since the last call (rate-limited); how many."""
        return self._bus_log.poll(self.drives)

    def stop(self) -> RunSummary | None:
        """Quick stop, disable, stop the loop, flush the recording, close everything."""
        if self._stopped:
            return None
        self._stopped = True
        self.notifier.stopping()
        loop = self.loop
        calibrating = self.service is not None and self.service.cancel_calibration("shutdown")
        if loop is not None and self.loop_thread is not None and self.loop_thread.alive:
            try:
                loop.post("shutdown").result(timeout=5.0)
            except (LoopError, DriveError, TimeoutError) as exc:
                self.log.error("shutdown command failed", reason=str(exc))
            if calibrating:  # let it end on the still-ticking (now disabled) loop
                deadline = time.monotonic() + 5.0
                while self.service is not None and self.service.calibrating \
                        and time.monotonic() < deadline:
                    time.sleep(0.05)
        if self.loop_thread is not None:
            self.loop_thread.stop()
        if self.online is not None:
            self.online.detach()
        if self.server is not None:
            self.server.stop()
        if self.recorder is not None:
            self.recorder.close()
            self.log.info("recording written", path=self.recorder.path,
                          rows=self.recorder.rows_written)
        if self.drives is not None:
            self.log_bus_events()
            with contextlib.suppress(DriveError):
                self.drives.close()
        if self.rig is not None:
            self.rig.close()
        summary = self.summary()
        self._bus_log.flush()
        self.events.close()
        self.notifier.close()
        return summary

    @property
    def loop_error(self) -> BaseException | None:
        """What killed the loop thread, if it died (the process then exits non-zero)."""
        return self.loop_thread.error if self.loop_thread is not None else None

    @property
    def scheduler(self) -> FixedRateScheduler | None:
        return self.loop_thread.scheduler if self.loop_thread is not None else None

    @property
    def rt_report(self) -> RealtimeReport | None:
        return self.loop_thread.rt_report if self.loop_thread is not None else None

    def summary(self) -> RunSummary | None:
        return self.loop_thread.summary() if self.loop_thread is not None else None
