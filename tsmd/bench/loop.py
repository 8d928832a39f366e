"""`tsmd bench loop`: how punctual the control loop is, beside the machine's own limit.

For each rate, the daemon's real loop (``Daemon`` without the socket) runs for ``--seconds``
against the simulated rig in real time, compensation on, with a 50 Hz sine setpoint written
from another thread as an API client would. ``--rig process`` (default) runs the rig as its
own process (``tsmd sim``) on python-can's ``udp_multicast`` bus, so the daemon process holds
only what it holds on the robot (master, loop, compensator); ``--rig thread`` keeps the rig in
the daemon's process on the ``virtual`` bus, as ``tsmd run --sim`` does, where the physics
competes with the loop for the GIL. Measured: tick lateness (wake-up after the absolute
deadline), SYNC period jitter (time between SYNC frames minus the period), overruns and CPU
time per tick. The "hostile clients" run repeats each rate with the API socket open and
another process connecting and closing as fast as it can (the churn that once took ticks).
``cyclictest`` (rt-tests), when installed, runs at the same time, priority and period: its
wake-up latency is what this machine allows any thread under the same load. Figures in
docs/benchmarks.md#loop.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import math
import os
import re
import shutil
import subprocess
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.config import default_sim_config
from tsmd.daemon import Daemon
from tsmd.errors import TsmdError
from tsmd.log import configure_logging
from tsmd.rt import set_fifo


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--seconds", type=float, default=60.0,
                        help="duration of each run (default 60)")
    parser.add_argument("--rates", default="250,1000", help="loop rates in Hz (default 250,1000)")
    parser.add_argument("--priority", type=int, default=80,
                        help="SCHED_FIFO priority for the loop and cyclictest (0: none)")
    parser.add_argument("--cpu", type=int, default=None, help="pin the loop and cyclictest here")
    parser.add_argument("--no-cyclictest", action="store_true")
    parser.add_argument("--rig", choices=("process", "thread"), default="process",
                        help="simulated rig in its own process (default) or in the daemon's")
    parser.add_argument("--no-hostile", action="store_true",
                        help="skip the run with a connect/close storm on the API socket")


@dataclass
class Stats:
    median_us: float
    p99_us: float
    p999_us: float
    max_us: float

    @classmethod
    def of(cls, values_s: NDArray[np.float64]) -> Stats:
        if values_s.size == 0:
            return cls(math.nan, math.nan, math.nan, math.nan)
        us = values_s * 1e6
        return cls(float(np.median(us)), float(np.percentile(us, 99)),
                   float(np.percentile(us, 99.9)), float(us.max()))

    def row(self) -> str:
        return (f"{self.median_us:9.1f} {self.p99_us:9.1f} {self.p999_us:9.1f} "
                f"{self.max_us:9.1f}")


@dataclass
class LoopResult:
    rate_hz: float
    ticks: int
    overruns: int
    lateness: Stats
    sync_jitter: Stats
    cpu_per_tick_us: Stats
    realtime: str
    faults: int
    seconds: float = 0.0
    churn_per_s: float | None = None
    """Connect attempts per second of the hostile client (None: quiet run)."""
    accepted_per_s: float | None = None


def run_loop(rate_hz: float, seconds: float, priority: int, cpu: int | None,
             rig: str = "process",
             on_measure_start: Callable[[], None] | None = None,
             hostile: bool = False) -> LoopResult:
    """The daemon's loop against the real-time simulated rig; timings of every tick and SYNC."""
    base = default_sim_config()
    rt = dataclasses.replace(base.loop.realtime, priority=priority, cpu=cpu, lock_memory=True)
    # The simulated drives (Python, over a software bus) answer late far more often than
    # hardware: stale-feedback and overrun faults are relaxed so the run measures the loop in
    # normal operation instead of a quick-stopped loop.
    loop_cfg = dataclasses.replace(base.loop, rate_hz=rate_hz, realtime=rt,
                                   overrun_fault_streak=10_000, stale_feedback_syncs=1000)
    drive_entries = [{**d, "stale_after_syncs": 1000, "heartbeat_timeout_ms": 2000,
                      "master_heartbeat_timeout_ms": 2000} for d in base.drives]
    config = dataclasses.replace(base, loop=loop_cfg, drives=drive_entries)
    rig_proc: subprocess.Popen[str] | None = None
    if rig == "process":
        group = f"ff15:7079:7468:6f6e:7473:6d64:{os.getpid() >> 16:x}:{os.getpid() & 0xFFFF:x}"
        config = dataclasses.replace(config, bus=dataclasses.replace(
            config.bus, interface="udp_multicast", channel=group))
        rig_proc = _start_rig_process(config)
    socket_dir = tempfile.TemporaryDirectory(prefix="tsmd-bench-") if hostile else None
    daemon = Daemon(config, sim=rig == "thread", api=hostile,
                    socket_path=f"{socket_dir.name}/tsmd.sock" if socket_dir else None)
    sync_times: list[float] = []
    storm: subprocess.Popen[str] | None = None
    try:
        daemon.start()
        assert daemon.loop is not None and daemon.drives is not None
        loop = daemon.loop
        drives = daemon.drives
        original_sync = drives.sync

        def timed_sync() -> None:
            sync_times.append(time.monotonic())
            original_sync()

        drives.sync = timed_sync  # type: ignore[method-assign]
        loop.post("enable").result(timeout=10.0)
        time.sleep(0.5)  # warm-up: enabling blocks the loop on purpose; measure after it
        assert daemon.scheduler is not None
        daemon.scheduler.times.clear()
        overruns0 = loop.stats.overruns
        sync_times.clear()
        if on_measure_start is not None:
            on_measure_start()
        stop = threading.Event()
        setter = threading.Thread(target=_sine_setpoints, args=(loop, stop, priority),
                                  daemon=True)
        accepted0 = daemon.server.accepted if daemon.server is not None else 0
        if daemon.socket_path is not None:
            storm = _start_churn(str(daemon.socket_path), seconds)
        setter.start()
        time.sleep(seconds)
        stop.set()
        setter.join()
        churn = _churn_rate(storm, seconds) if storm is not None else None
        accepted = (daemon.server.accepted - accepted0 if daemon.server is not None else None)
        assert daemon.scheduler is not None
        times = daemon.scheduler.times
        report = daemon.rt_report
        realtime = "SCHED_OTHER"
        if report is not None:
            parts = []
            if report.fifo_priority:
                parts.append(f"SCHED_FIFO {report.fifo_priority}")
            if report.cpu is not None:
                parts.append(f"CPU {report.cpu}")
            if report.memory_locked:
                parts.append("mlockall")
            realtime = ", ".join(parts) or "SCHED_OTHER"
        syncs = np.diff(np.asarray(sync_times))
        result = LoopResult(
            rate_hz=rate_hz, ticks=times.count, overruns=loop.stats.overruns - overruns0,
            lateness=Stats.of(times.lateness()),
            sync_jitter=Stats.of(np.abs(syncs - 1.0 / rate_hz)),
            cpu_per_tick_us=Stats.of(times.cpu()), realtime=realtime,
            faults=loop.stats.faults, seconds=seconds, churn_per_s=churn,
            accepted_per_s=accepted / seconds if accepted is not None and hostile else None)
    finally:
        if storm is not None and storm.poll() is None:
            storm.kill()
            storm.communicate()
        daemon.stop()
        if socket_dir is not None:
            socket_dir.cleanup()
        if rig_proc is not None:
            rig_proc.terminate()
            rig_proc.communicate(timeout=10)
    return result


_RIG_MAIN = """
import argparse, sys
from tsmd.commands import sim
parser = argparse.ArgumentParser()
sim.add_arguments(parser)
sys.exit(sim.main(parser.parse_args(sys.argv[1:])))
"""


def _start_rig_process(config: Any) -> subprocess.Popen[str]:
    """``tsmd sim`` on the bus of ``config``; returns once it serves the bus."""
    import sys
    import tempfile

    import yaml

    from tsmd.config import TsmdConfig

    assert isinstance(config, TsmdConfig)
    data = dataclasses.asdict(config)
    handle = tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False)  # noqa: SIM115
    with handle:
        yaml.safe_dump(data, handle)
    argv = ["--interface", config.bus.interface, "--channel", config.bus.channel,
            "--config", handle.name, "--status-every", "0"]
    def ordinary_child() -> None:
        # On the robot the drives are hardware and take no CPU from the host; here the rig
        # process runs under the ordinary scheduler so it never preempts the daemon's threads
        # (it is not starved either: its answers only need to arrive, the loop never waits).
        with contextlib.suppress(OSError):
            os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))

    proc = subprocess.Popen(
        [sys.executable, "-c", _RIG_MAIN, *argv], preexec_fn=ordinary_child,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    line = proc.stdout.readline()  # the rig prints one line when it starts serving
    os.unlink(handle.name)
    if proc.poll() is not None or not line:
        err = proc.stderr.read() if proc.stderr else ""
        raise TsmdError(f"the simulated rig process did not start: {err.strip()[:300]}")
    return proc


_CHURN_MAIN = """
import socket, sys, time
path, seconds = sys.argv[1], float(sys.argv[2])
end = time.monotonic() + seconds
attempts = 0
while time.monotonic() < end:
    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    s.setblocking(False)
    try:
        s.connect(path)
    except OSError:
        pass
    s.close()
    attempts += 1
print(attempts)
"""


def _start_churn(path: str, seconds: float) -> subprocess.Popen[str]:
    """A hostile client in its own process: connect and close as fast as it can."""
    import sys

    return subprocess.Popen([sys.executable, "-c", _CHURN_MAIN, path, str(seconds)],
                            stdout=subprocess.PIPE, text=True)


def _churn_rate(proc: subprocess.Popen[str], seconds: float) -> float:
    out, _ = proc.communicate(timeout=seconds + 30)
    return int(out.strip() or 0) / seconds


def _sine_setpoints(loop: Any, stop: threading.Event, priority: int) -> None:
    if priority > 0:  # as the daemon's API thread does (tsmd.rt.helper_thread_priority)
        set_fifo(1)
    t0 = time.monotonic()
    while not stop.wait(0.02):
        t = time.monotonic() - t0
        loop.setpoint.set((60.0 * math.sin(2 * math.pi * 0.1 * t),
                           30.0 * math.sin(2 * math.pi * 0.2 * t)))


@dataclass
class CyclictestResult:
    lateness: Stats
    samples: int
    command: str
    late_by_a_period: int
    """Wake-ups later than one period: stalls no thread on this machine could avoid."""


class Cyclictest:
    """``cyclictest`` at the loop's priority and period, running beside the loop."""

    def __init__(self, rate_hz: float, seconds: float, priority: int, cpu: int | None) -> None:
        tool = shutil.which("cyclictest")
        if tool is None:
            raise TsmdError("cyclictest is not installed (Debian package rt-tests)")
        period_us = round(1e6 / rate_hz)
        self.cmd = [tool, "-q", "-m", "-t", "1", "-i", str(period_us), "-D",
                    f"{max(1, round(seconds))}s", "-h", "20000"]
        if priority > 0:
            self.cmd += ["-p", str(priority)]
        if cpu is not None:
            self.cmd += ["-a", str(cpu)]
        self.seconds = seconds
        self.period_us = period_us
        self.proc: subprocess.Popen[str] | None = None

    def start(self) -> None:
        self.proc = subprocess.Popen(self.cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True)

    def result(self) -> CyclictestResult:
        if self.proc is None:
            raise TsmdError("cyclictest was not started")
        out, err = self.proc.communicate(timeout=self.seconds + 60)
        hist = [(int(a), int(b)) for a, b in re.findall(r"^(\d+) (\d+)$", out, re.M)]
        counts = np.array([c for _, c in hist], dtype=np.int64)
        if self.proc.returncode != 0 or counts.sum() == 0:
            raise TsmdError(f"cyclictest failed ({self.proc.returncode}): {err.strip()[:200]}")
        lat_us = np.array([us for us, _ in hist], dtype=float)
        stats = Stats.of(np.repeat(lat_us, counts) * 1e-6)
        max_match = re.search(r"# Max Latencies: (\d+)", out)
        if max_match is not None:  # beyond the histogram's range
            stats.max_us = max(stats.max_us, float(max_match.group(1)))
        late = int(counts[lat_us >= self.period_us].sum())
        overflow = re.search(r"# Histogram Overflows: (\d+)", out)
        if overflow is not None:
            late += int(overflow.group(1))
        return CyclictestResult(stats, int(counts.sum()), " ".join(self.cmd[1:]), late)


def main(args: argparse.Namespace) -> int:
    configure_logging("console", level="warning")
    rates = [float(r) for r in args.rates.split(",") if r.strip()]
    if not rates or any(not 10 <= r <= 1000 for r in rates):
        raise TsmdError(f"--rates {args.rates!r}: give rates between 10 and 1000 Hz")
    if args.seconds <= 0:
        raise TsmdError("--seconds must be positive")
    load = os.getloadavg()
    print(f"tsmd bench loop: {args.seconds:g} s per run, rig in a {args.rig}, "
          f"{os.cpu_count()} CPUs, load average before {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    print("lateness = wake-up after the absolute deadline; jitter = |SYNC interval - period|")
    header = f"{'':34} {'median':>9} {'p99':>9} {'p99.9':>9} {'max':>9}  (us)"
    goals_ok = True
    for rate in rates:
        tester = None
        if not args.no_cyclictest and shutil.which("cyclictest") is not None:
            tester = Cyclictest(rate, args.seconds, args.priority, args.cpu)
        result = run_loop(rate, args.seconds, args.priority, args.cpu, args.rig,
                          on_measure_start=tester.start if tester is not None else None)
        hostile = (None if args.no_hostile else
                   run_loop(rate, args.seconds, args.priority, args.cpu, args.rig, hostile=True))
        ct = tester.result() if tester is not None else None
        pct = 100.0 * result.overruns / max(result.ticks, 1)
        print(f"\n{rate:g} Hz ({result.realtime}): {result.ticks} ticks, {result.overruns} "
              f"overruns ({pct:.3f} %), {result.faults} faults")
        print(header)
        print(f"{'loop tick lateness':34} {result.lateness.row()}")
        print(f"{'SYNC period jitter':34} {result.sync_jitter.row()}")
        print(f"{'loop CPU per tick':34} {result.cpu_per_tick_us.row()}")
        if ct is not None:
            print(f"{'cyclictest latency (machine limit)':34} {ct.lateness.row()}")
            late_pct = 100.0 * ct.late_by_a_period / ct.samples
            print(f"  cyclictest {ct.command}: {ct.samples} samples, {ct.late_by_a_period} "
                  f"woke more than a period late ({late_pct:.3f} %)")
            ratio = result.lateness.p99_us / max(ct.lateness.p99_us, 1.0)
            ok = ratio <= 1.5
            goals_ok &= ok
            print(f"  goal p99 lateness <= 1.5 x cyclictest p99: {ratio:.2f} x -> "
                  f"{'met' if ok else 'NOT met'}")
        else:
            print("  cyclictest not run (not installed or --no-cyclictest)")
        if rate <= 250:
            ok = result.overruns == 0
            print(f"  goal no overrun at {rate:g} Hz: {'met' if ok else 'NOT met'}")
        else:
            ok = pct <= 0.1
            print(f"  goal <= 0.1 % overruns at {rate:g} Hz: {'met' if ok else 'NOT met'}")
        goals_ok &= ok
        if hostile is not None:
            goals_ok &= _print_hostile(result, hostile)
    load = os.getloadavg()
    print(f"\nload average after {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}; "
          f"goals {'all met' if goals_ok else 'NOT all met'}")
    return 0


def _print_hostile(quiet: LoopResult, hostile: LoopResult) -> bool:
    """The hostile-clients row: overruns and tick rate during a churn storm vs quiet."""
    def rate(r: LoopResult) -> float:
        return r.ticks / r.seconds if r.seconds else math.nan

    pct = 100.0 * hostile.overruns / max(hostile.ticks, 1)
    quiet_pct = 100.0 * quiet.overruns / max(quiet.ticks, 1)
    print(f"  hostile clients ({hostile.churn_per_s or 0:.0f} connects/s tried, "
          f"{hostile.accepted_per_s or 0:.0f}/s accepted): {hostile.ticks} ticks "
          f"({rate(hostile):.1f}/s vs {rate(quiet):.1f}/s quiet), {hostile.overruns} overruns "
          f"({pct:.3f} % vs {quiet_pct:.3f} % quiet), {hostile.faults} faults")
    print(f"{'loop tick lateness, hostile clients':34} {hostile.lateness.row()}")
    ok = rate(hostile) >= 0.99 * rate(quiet) and pct <= max(2.0 * quiet_pct, 0.1)
    print(f"  goal hostile clients take no ticks (tick rate >= 99 % of quiet, overruns <= "
          f"max(2 x quiet, 0.1 %)): {'met' if ok else 'NOT met'}")
    return ok
