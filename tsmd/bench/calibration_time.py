"""`tsmd bench calibration --time`: wall time, CPU and peak RSS of a whole calibration in
lockstep (as ``tsmd calibrate --sim`` runs it), and where a tick's time goes.

Two runs in one process. The first is the protocol itself, timed only at its coarse seams
(the plant's ``step``, each sweep's ``run``), so its wall time is the figure to compare with
the < 30 s target. The second plays ``--split-ticks`` ticks of a paper sweep with a timer
around every layer of the stack (plant, simulated drives, EM tracker, CAN bus, CANopen master,
control loop, trajectory bookkeeping); the timers add their own cost, printed beside the split.
``--plant-step-us`` makes every plant step last at least that long (busy wait, the plant's
own work included): the target's condition is a plant step of up to 100 us.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import resource
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import Plant, PlantStep, load_plant
from tsmd.calibration import fast_protocol, paper_protocol, run_calibration
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.profile import DeviceModel
from tsmd.replay import LockstepRunner

SPLIT_ORDER = ("plant", "simulated drives", "EM tracker", "CAN bus", "CANopen master",
               "control loop", "trajectory bookkeeping")


class PacedPlant:
    """A plant whose ``step`` lasts at least ``step_us`` (busy wait after its own work): the
    cost of a heavier physics model, with the same physics.

    ``cpu=True`` paces on this thread's CPU time instead of the wall clock: every step then
    costs the process ``step_us`` of CPU whatever else runs on the machine, so the run's CPU
    time is what an idle core would take (a loaded machine only stretches the wall time).
    """

    def __init__(self, plant: Plant, step_us: float = 0.0, *, cpu: bool = False) -> None:
        self.plant = plant
        self.step_s = max(step_us, 0.0) * 1e-6
        self.clock = time.thread_time if cpu else time.perf_counter
        self.spent_s = 0.0
        """Time inside ``step`` (own work and wait) on the pacing clock."""

    def reset(self) -> None:
        self.plant.reset()

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> Any:
        clock = self.clock
        t0 = clock()
        answer = self.plant.step(dt_s, knob_deg)
        end = t0 + self.step_s
        t1 = clock()
        while t1 < end:
            t1 = clock()
        self.spent_s += t1 - t0
        return answer


@dataclass
class TimeRun:
    """What the protocol run cost."""

    protocol: str
    ticks: int
    wall_s: float
    cpu_s: float
    """This process's CPU (user + system) during the run."""
    plant_s: float
    ticking_s: float
    """Wall time inside the runner (the ticks and their per-sweep bookkeeping)."""
    rss_MiB: float
    accepted: bool
    plant_step_us: float
    pace_cpu: bool = False
    notes: list[str] = field(default_factory=list)
    worker_cpu_s: float = math.nan
    """CPU of the identification worker (child processes ended during the run)."""


def _cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def _children_cpu_s() -> float:
    """CPU (user + system) of the child processes that have ended and been waited for."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _wait_for_children(timeout_s: float = 10.0) -> None:
    """Let the identification worker (shut down without waiting) exit and be reaped, so that its
    CPU shows in ``RUSAGE_CHILDREN``."""
    deadline = time.monotonic() + timeout_s
    while multiprocessing.active_children() and time.monotonic() < deadline:
        time.sleep(0.02)


def _rss_MiB() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


class _TimedRunner:
    """The runner with the wall time of its ``run`` calls added up (once per sweep)."""

    def __init__(self, runner: LockstepRunner) -> None:
        self.runner = runner
        self.run_s = 0.0

    @property
    def period_s(self) -> float:
        return self.runner.period_s

    def run(self, *args: Any, **kwargs: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return self.runner.run(*args, **kwargs)
        finally:
            self.run_s += time.perf_counter() - t0


def time_protocol(config: TsmdConfig, device: DeviceModel, *, fast: bool = False,
                  plant_step_us: float = 0.0, seed: int = 0, pace_cpu: bool = False) -> TimeRun:
    """One calibration in lockstep on the config's plant, paced to ``plant_step_us``."""
    plant = PacedPlant(load_plant(config.sim.plant, config.sim.params), plant_step_us,
                       cpu=pace_cpu)
    proto = fast_protocol() if fast else paper_protocol()
    w0, c0, k0 = time.perf_counter(), _cpu_s(), _children_cpu_s()
    accepted = True
    notes: list[str] = []
    with LockstepRunner(config, seed=seed, plant=plant) as runner:
        timed = _TimedRunner(runner)
        try:
            cal = run_calibration(timed, "time", device,
                                  protocol=proto, isolate=True,  # as `calibrate --sim`
                                  live_loop=False)
            notes = cal.notes
        except Exception as exc:
            accepted = False
            notes = [f"{type(exc).__name__}: {exc}"]
        ticks = runner.loop.stats.ticks
    wall_s, cpu_s = time.perf_counter() - w0, _cpu_s() - c0
    _wait_for_children()
    return TimeRun(proto.name, ticks, wall_s, cpu_s, plant.spent_s, timed.run_s, _rss_MiB(),
                   accepted, plant_step_us, pace_cpu, notes, _children_cpu_s() - k0)


class _Timers:
    """Named wall-time sums; :meth:`wrap` times one callable into one name."""

    def __init__(self) -> None:
        self.s: dict[str, float] = {}

    def wrap(self, name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        clock = time.perf_counter
        sums = self.s
        sums.setdefault(name, 0.0)

        def timed(*args: Any, **kwargs: Any) -> Any:
            t0 = clock()
            try:
                return fn(*args, **kwargs)
            finally:
                sums[name] += clock() - t0

        return timed


class _TimedPlant:
    """The rig's plant with its ``step`` timed."""

    def __init__(self, plant: Plant, timers: _Timers) -> None:
        self.reset = plant.reset
        self.step = timers.wrap("plant", plant.step)


def _instrument(runner: LockstepRunner, timers: _Timers) -> None:
    """Timers on the seams between the layers (instance attributes: nothing global)."""
    rig, loop, drives = runner.rig, runner.loop, runner.drives
    for side, bus in (("bus_rig", rig.bus), ("bus_master", getattr(drives, "bus", None))):
        for name in ("send", "send_owned", "recv"):
            if hasattr(bus, name):
                setattr(bus, name, timers.wrap(side, getattr(bus, name)))
    if getattr(rig, "_send_owned", None) is not None:  # bound at construction
        rig._send_owned = getattr(rig.bus, "send_owned")  # noqa: B009
    rig.plant = _TimedPlant(rig.plant, timers)
    if loop._after_sync is not None:
        loop._after_sync = timers.wrap("rig", loop._after_sync)
    if loop._tip_source is not None:
        loop._tip_source = timers.wrap("tracker", loop._tip_source)
    for name in ("pump", "poll_events", "feedback", "write_targets", "sync"):
        setattr(drives, name, timers.wrap("master", getattr(drives, name)))
    setattr(loop, "step", timers.wrap("loop", loop.step))  # noqa: B010


def split_ticks(config: TsmdConfig, ticks: int, *, plant_step_us: float = 0.0,
                seed: int = 0) -> tuple[dict[str, float], float, float]:
    """Per-tick wall time of each layer over ``ticks`` ticks of a paper sweep (us), the timed
    total per tick and the same ticks' total without timers (us)."""
    period_s = config.loop.period_s
    t = np.arange(ticks) * period_s
    q = np.column_stack([90.0 * np.sin(2 * np.pi * 0.04 * t), np.zeros(ticks)])
    totals = []
    split: dict[str, float] = {}
    for timed in (False, True):
        plant = PacedPlant(load_plant(config.sim.plant, config.sim.params), plant_step_us)
        with LockstepRunner(config, seed=seed, plant=plant) as runner:
            timers = _Timers()
            if timed:
                _instrument(runner, timers)
            t0 = time.perf_counter()
            runner.run(t, q, compensate=False)
            total = time.perf_counter() - t0
        totals.append(total / ticks * 1e6)
        if timed:
            s = {k: v / ticks * 1e6 for k, v in timers.s.items()}
            split = {
                "plant": s["plant"],
                "simulated drives": s["rig"] - s["plant"] - s["bus_rig"],
                "EM tracker": s.get("tracker", 0.0),
                "CAN bus": s["bus_rig"] + s["bus_master"],
                "CANopen master": s["master"] - s["bus_master"],
                "control loop": s["loop"] - s["rig"] - s.get("tracker", 0.0) - s["master"],
                "trajectory bookkeeping": totals[-1] - s["loop"],
            }
    return split, totals[1], totals[0]


class _KnobLog:
    """The rig's plant, remembering every knob position it was stepped to."""

    def __init__(self, plant: Plant) -> None:
        self.plant = plant
        self.knobs: list[NDArray[np.float64]] = []

    def reset(self) -> None:
        self.plant.reset()

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> Any:
        self.knobs.append(knob_deg.copy())
        return self.plant.step(dt_s, knob_deg)


def min_cpu_per_tick(config: TsmdConfig, *, reps: int = 30, ticks: int = 1000,
                     seed: int = 0) -> tuple[float, float, float, float]:
    """CPU of this thread per tick (us), min and median over ``reps`` runs of ``ticks`` ticks
    of a paper sweep, and of the plant's ``step`` alone along the same knob path. On a shared
    machine the minimum is the figure that other jobs disturb least."""
    period_s = config.loop.period_s
    n = reps * ticks
    t = np.arange(n) * period_s
    q = np.column_stack([90.0 * np.sin(2 * np.pi * 0.04 * t), np.zeros(n)])
    log = _KnobLog(load_plant(config.sim.plant, config.sim.params))
    tick_us = []
    with LockstepRunner(config, seed=seed, plant=log) as runner:
        start = len(log.knobs)
        for k in range(reps):
            c0 = time.thread_time()
            runner.run(t[k * ticks:(k + 1) * ticks], q[k * ticks:(k + 1) * ticks], False)
            tick_us.append((time.thread_time() - c0) / ticks * 1e6)
        knobs = log.knobs[start:]
    plant = load_plant(config.sim.plant, config.sim.params)
    plant.reset()
    plant_us = []
    chunk = max(len(knobs) // reps, 1)
    for k in range(reps):
        part = knobs[k * chunk:(k + 1) * chunk]
        c0 = time.thread_time()
        for knob in part:
            plant.step(period_s, knob)
        plant_us.append((time.thread_time() - c0) / max(len(part), 1) * 1e6)
    return (min(tick_us), float(np.median(tick_us)), min(plant_us), float(np.median(plant_us)))


def report(run: TimeRun, split: dict[str, float], timed_us: float, plain_us: float,
           split_ticks_n: int, cpu: tuple[float, float, float, float]) -> list[str]:
    per_tick = run.ticking_s / max(run.ticks, 1) * 1e6
    plant_us = run.plant_s / max(run.ticks, 1) * 1e6
    lines = [
        f"{run.protocol} protocol in lockstep, plant step paced to >= {run.plant_step_us:g} us "
        f"of {'CPU' if run.pace_cpu else 'wall'} time: "
        f"{'accepted' if run.accepted else 'NOT accepted'}; {run.ticks} ticks",
        f"  wall {run.wall_s:.1f} s (target < 30 s), CPU of this process {run.cpu_s:.1f} s "
        f"+ identification worker {run.worker_cpu_s:.1f} s, peak RSS {run.rss_MiB:.0f} MiB "
        f"(this process), load average {_loadavg()} on {os.cpu_count()} CPUs",
        f"  ticking {run.ticking_s:.1f} s wall = {per_tick:.1f} us/tick; plant.step "
        f"{plant_us:.1f} us " + ("of CPU" if run.pace_cpu else f"(stack {per_tick - plant_us:.1f})")
        + f"; outside the ticks (identification, plan, fit) {run.wall_s - run.ticking_s:.1f} s",
    ]
    lines += [f"  {note}" for note in run.notes]
    lines.append(f"where a tick goes ({split_ticks_n} ticks of a 0.04 Hz +-90 deg sweep, us/tick "
                 f"wall; timers add {timed_us - plain_us:.1f} us: {timed_us:.1f} timed, "
                 f"{plain_us:.1f} without):")
    for name in SPLIT_ORDER:
        value = split.get(name, float("nan"))
        lines.append(f"  {name:<24} {value:7.1f}  {100.0 * value / timed_us:5.1f} %")
    lines.append(f"CPU per tick, unpaced plant (min / median of 30 runs of 1000 ticks): whole "
                 f"tick {cpu[0]:.1f} / {cpu[1]:.1f} us, plant.step alone {cpu[2]:.1f} / "
                 f"{cpu[3]:.1f} us")
    return lines


def _loadavg() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


def main_time(device: DeviceModel, *, fast: bool, plant_step_us: float, split_n: int,
              seed: int = 0, config: TsmdConfig | None = None,
              pace_cpu: bool = False) -> list[str]:
    """The ``--time`` figures as printed lines."""
    cfg = config or default_sim_config()
    run = time_protocol(cfg, device, fast=fast, plant_step_us=plant_step_us, seed=seed,
                        pace_cpu=pace_cpu)
    split, timed_us, plain_us = split_ticks(cfg, split_n, plant_step_us=plant_step_us, seed=seed)
    cpu = min_cpu_per_tick(cfg, seed=seed)
    return report(run, split, timed_us, plain_us, split_n, cpu)


__all__ = ["PacedPlant", "PlantStep", "TimeRun", "main_time", "min_cpu_per_tick", "split_ticks",
           "time_protocol"]
