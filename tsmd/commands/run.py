"""`tsmd run`: the daemon (drives, loop, socket API), on the robot or on the simulated rig.

``--demo`` plays a sine on both knobs through the socket, exactly as a client would (enable,
subscribe, set at 50 Hz), first without compensation and then with it, and prints the tip's
tracking error of each half. With ``--sim`` the demo is on unless ``--no-demo``.
"""

from __future__ import annotations

import argparse
import math
import signal
import sys
import threading
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np

from tsmd.api.client import ApiClient, ApiClientError
from tsmd.config import DEFAULT_CONFIG_PATH, TsmdConfig, default_sim_config, load_config
from tsmd.daemon import Daemon
from tsmd.errors import TsmdError
from tsmd.log import configure_logging

DEMO_SET_HZ = 50.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--config", metavar="FILE",
                        help=f"configuration file (default {DEFAULT_CONFIG_PATH}; with --sim "
                             "the packaged simulation config)")
    parser.add_argument("--sim", action="store_true",
                        help="run on the in-process simulated rig (real time)")
    parser.add_argument("--duration", type=float, metavar="S",
                        help="stop after S seconds (default: run until SIGTERM/SIGINT)")
    demo = parser.add_mutually_exclusive_group()
    demo.add_argument("--demo", dest="demo", action="store_true", default=None,
                      help="play a sine on both knobs through the socket (default with --sim)")
    demo.add_argument("--no-demo", dest="demo", action="store_false")
    parser.add_argument("--socket", metavar="PATH", help="socket path (overrides api.socket_path)")
    parser.add_argument("--profile", metavar="FILE", help="catheter profile file to load instead "
                                                           "of profiles.active")
    parser.add_argument("--home", action="store_true",
                        help="home every drive that has a homing method before the loop starts "
                             "(drives[i].homing; a search moves the knobs)")
    parser.add_argument("--log-format", choices=("auto", "json", "console"), default="auto")
    parser.add_argument("--realtime-priority", type=int, metavar="N",
                        help="SCHED_FIFO priority of the loop thread, 1-99, or 0 for normal "
                             "scheduling (overrides loop.realtime.priority; the packaged "
                             "simulation config asks for 0, so that any user can run it)")


def _config(args: argparse.Namespace) -> TsmdConfig:
    if args.config is not None:
        config = load_config(args.config)
    elif args.sim:
        config = default_sim_config()
    else:
        config = load_config(DEFAULT_CONFIG_PATH)
    priority = getattr(args, "realtime_priority", None)
    if priority is None:
        return config
    realtime = replace(config.loop.realtime, priority=priority)
    return replace(config, loop=replace(config.loop, realtime=realtime))


@dataclass
class DemoPhase:
    method: str
    samples: list[dict[str, Any]] = field(default_factory=list)

    def tip_rmse_deg(self) -> tuple[float, float] | None:
        rows = [(s["q"], s["tip"]) for s in self.samples
                if s.get("tip") is not None and None not in s["tip"] and None not in s["q"]]
        if len(rows) < 10:
            return None
        q = np.array([r[0] for r in rows], dtype=float)
        tip = np.array([r[1] for r in rows], dtype=float)
        rmse = np.sqrt(np.mean((tip - q) ** 2, axis=0))
        return float(rmse[0]), float(rmse[1])


class Demo:
    """A client thread: sine setpoints on both knobs, compensation off then on."""

    def __init__(self, socket_path: Path, duration_s: float | None, stop: threading.Event) -> None:
        self.socket_path = socket_path
        self.duration_s = duration_s
        self.stop = stop
        self.phases: list[DemoPhase] = []
        self.error: str | None = None
        self.thread = threading.Thread(target=self._run, name="tsmd-demo", daemon=True)

    def _run(self) -> None:
        try:
            with ApiClient(self.socket_path, timeout_s=15.0) as client:
                self._play(client)
        except (ApiClientError, OSError) as exc:
            if not self.stop.is_set():
                self.error = str(exc)

    def _play(self, client: ApiClient) -> None:
        status = client.call("status")
        wanted = status["compensation"]["method"]
        methods = ["none", wanted] if status["profile"] and wanted != "none" else ["none"]
        if self.duration_s is None:  # until stopped: only the configured compensation
            methods = methods[-1:]
        client.call("enable")
        total = self.duration_s if self.duration_s is not None else math.inf
        phase_s = max((total - 0.5) / len(methods), 1.0)
        for method in methods:
            if self.stop.is_set():
                return
            client.call("compensation", enabled=method != "none")
            phase = DemoPhase(method)
            self.phases.append(phase)
            self._sine(client, phase, phase_s)

    def _sine(self, client: ApiClient, phase: DemoPhase, phase_s: float) -> None:
        cycles = max(1, round(phase_s * 0.1)) if math.isfinite(phase_s) else 1
        f_hz = cycles / phase_s if math.isfinite(phase_s) else 0.1
        start = time.monotonic()
        k = 0
        while not self.stop.is_set():
            t = k / DEMO_SET_HZ
            if t > phase_s:
                return
            q = [60.0 * math.sin(2 * math.pi * f_hz * t),
                 30.0 * math.sin(2 * math.pi * 2 * f_hz * t)]
            client.call("set", q=q)
            if t >= 0.2 * min(phase_s, 10.0):  # skip the start-up transient
                phase.samples.append(client.call("get")["sample"])
            k += 1
            delay = start + k / DEMO_SET_HZ - time.monotonic()
            if delay > 0:
                self.stop.wait(delay)


def main(args: argparse.Namespace) -> int:
    if args.duration is not None and not 0.0 < args.duration < math.inf:
        raise TsmdError(f"--duration must be a positive number of seconds, got {args.duration}")
    if args.realtime_priority is not None and not 0 <= args.realtime_priority <= 99:
        raise TsmdError(f"--realtime-priority must be 0-99, got {args.realtime_priority}")
    configure_logging(args.log_format)
    config = _config(args)
    daemon = Daemon(config, sim=args.sim, socket_path=args.socket, profile_path=args.profile,
                    home_at_start=args.home)

    def on_signal(signum: int, frame: FrameType | None) -> None:
        daemon.shutdown_requested.set()

    previous = {s: signal.signal(s, on_signal) for s in (signal.SIGTERM, signal.SIGINT)}
    demo: Demo | None = None
    try:
        daemon.start()
        if args.demo or (args.demo is None and args.sim):
            assert daemon.socket_path is not None
            demo = Demo(daemon.socket_path, args.duration, daemon.shutdown_requested)
            demo.thread.start()
        daemon.wait(args.duration)
    finally:
        if demo is not None:
            demo.stop.set()
            demo.thread.join(5.0)
        summary = daemon.stop()
        for s, handler in previous.items():
            signal.signal(s, handler)
    if summary is None:
        return 1
    print(f"tsmd run: {summary.ticks} ticks at {config.loop.rate_hz:g} Hz, "
          f"{summary.overruns} overruns, lateness p99 {summary.lateness_p99_ms:.3f} ms "
          f"(max {summary.lateness_max_ms:.3f} ms), final state {summary.state}"
          + (f" ({summary.fault})" if summary.fault else ""))
    rig = daemon.rig
    if rig is not None:  # the simulated catheter keeps wall time: say so when it could not
        print(f"  simulated rig: {rig.ticks} periods stepped, {rig.stalls} stalls"
              + (f" ({rig.stalled_s:.3f} s of physics skipped)" if rig.stalls else ""))
    if demo is not None:
        for phase in demo.phases:
            rmse = phase.tip_rmse_deg()
            text = (f"tip tracking RMSE phi1 {rmse[0]:.2f} deg, phi2 {rmse[1]:.2f} deg"
                    if rmse else "too short to measure")
            print(f"  demo, compensation {phase.method}: {len(phase.samples)} samples, {text}")
        if demo.error:
            print(f"  demo stopped: {demo.error}", file=sys.stderr)
    if daemon.loop_error is not None:
        print(f"tsmd run: the control loop stopped: {daemon.loop_error!r}", file=sys.stderr)
        return 1
    return 0 if demo is None or demo.error is None else 1
