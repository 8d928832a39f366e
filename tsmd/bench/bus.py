"""`tsmd bench bus`: CAN traffic and timing of the drive layer.

Figures: frames per tick, bus load at the configured bit rate (frame bits counted exactly,
stuff bits included, from the real frames), master CPU time per tick, SYNC-to-last-TPDO latency
in real time (virtual bus, rig thread), lockstep speed (simulated seconds per wall second) of the
drive layer, and of the whole stack as calibration runs it, split into stack and plant.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time

import can
import numpy as np

from simrig.lockstep_bus import LockstepBus
from simrig.plant import Plant, PlantStep, load_plant
from simrig.rig import DEFAULT_PLANT, open_sim_rig
from tsmd.replay import LockstepRunner


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--ticks", type=int, default=5000,
                        help="lockstep ticks for frames, bus load and master CPU (default 5000)")
    parser.add_argument("--latency-ticks", type=int, default=1000,
                        help="real-time SYNCs for the latency figure (default 1000)")
    parser.add_argument("--speed-seconds", type=float, default=700.0,
                        help="simulated seconds for the lockstep speed figure (default 700: "
                             "the calibration protocol)")
    parser.add_argument("--stack-seconds", type=float, default=120.0,
                        help="simulated seconds of the whole-stack split (loop + master + rig, "
                             "as calibration runs it; default 120, 0: skip)")
    parser.add_argument("--only-stack", action="store_true",
                        help="only the whole-stack split (skip frames, latency, drive layer)")
    parser.add_argument("--rate-hz", type=float, default=250.0)
    parser.add_argument("--bitrate", type=int, default=1_000_000)
    parser.add_argument("--seed", type=int, default=0)


def main(args: argparse.Namespace) -> int:
    period_s = 1.0 / args.rate_hz
    print(f"tsmd bench bus: 2 drives, {args.rate_hz:g} Hz ({period_s * 1e3:g} ms), "
          f"{args.bitrate / 1e6:g} Mbit/s")
    if not args.only_stack:
        for line in measure_traffic(args.ticks, period_s, args.bitrate, args.seed):
            print(line)
        for line in measure_latency(args.latency_ticks, period_s, args.seed):
            print(line)
        for line in measure_speed(args.speed_seconds, period_s, args.seed):
            print(line)
    if args.stack_seconds > 0:
        print(f"load average before the stack split: {_loadavg()}")
        for line in measure_stack(args.stack_seconds, args.seed):
            print(line)
    return 0


def _loadavg() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


# -- CAN frame bits ---------------------------------------------------------------------------
def _crc15(bits: list[int]) -> int:
    crc = 0
    for b in bits:
        nxt = b ^ ((crc >> 14) & 1)
        crc = (crc << 1) & 0x7FFF
        if nxt:
            crc ^= 0x4599
    return crc


def frame_bits(can_id: int, data: bytes) -> int:
    """Bits a classic base-format data frame occupies on the wire, stuff bits and IFS included."""
    bits = [0]  # SOF
    bits += [(can_id >> i) & 1 for i in range(10, -1, -1)]
    bits += [0, 0, 0]  # RTR, IDE, r0
    bits += [(len(data) >> i) & 1 for i in range(3, -1, -1)]
    for byte in data:
        bits += [(byte >> i) & 1 for i in range(7, -1, -1)]
    crc = _crc15(bits)
    bits += [(crc >> i) & 1 for i in range(14, -1, -1)]
    stuffed = 0
    run_bit, run_len = bits[0], 1
    for b in bits[1:]:
        if b == run_bit:
            run_len += 1
            if run_len == 5:
                stuffed += 1
                run_bit, run_len = 1 - b, 1  # the stuff bit starts a new run
                continue
        else:
            run_bit, run_len = b, 1
    # CRC delimiter, ACK slot + delimiter, EOF (7), intermission (3)
    return len(bits) + stuffed + 1 + 2 + 7 + 3


def worst_case_frame_bits(dlc: int) -> int:
    """Upper bound with maximal stuffing (CiA / Davis et al. formula)."""
    return 47 + 8 * dlc + (34 + 8 * dlc - 1) // 4


# -- measurements ------------------------------------------------------------------------------
class _Tap(can.Listener):
    """Counts every frame on the bus during a window (the master's and the drives')."""

    def __init__(self) -> None:
        self.frames: list[tuple[int, bytes]] = []

    def on_message_received(self, msg: can.Message) -> None:
        self.frames.append((msg.arbitration_id, bytes(msg.data)))

    def drain(self, bus: can.BusABC) -> None:
        """Everything ``bus`` (an observer on the channel) has seen so far."""
        while (msg := bus.recv(0)) is not None:
            self.on_message_received(msg)


def _spring() -> object:
    class Spring:
        def reset(self) -> None:
            pass

        def step(self, dt_s: float, knob_deg: np.ndarray) -> PlantStep:
            return PlantStep(tip_deg=1.3 * knob_deg, knob_torque_Nm=0.002 * knob_deg)

    return Spring()


def _trajectory(n: int, period_s: float) -> np.ndarray:
    t = np.arange(n) * period_s
    q = 60.0 * np.sin(2 * np.pi * 0.04 * t)
    return np.stack([q, -0.5 * q], axis=1)


def measure_traffic(ticks: int, period_s: float, bitrate: int, seed: int) -> list[str]:
    channel = f"tsmd-bench-traffic-{os.getpid()}"
    drives, rig = open_sim_rig(None, None, period_s, seed=seed, channel=channel)
    # A third node on the lockstep channel sees every frame of the master and the drives,
    # as a bus analyser would; it is read between ticks, outside the timed sections.
    observer = LockstepBus(channel)
    try:
        drives.boot()
        drives.enable()
        tap = _Tap()
        while observer.recv(0) is not None:  # boot traffic
            pass
        q = _trajectory(ticks, period_s)
        per_tick: list[int] = []
        cpu_ns: list[int] = []
        clock = time.thread_time_ns
        for k in range(ticks):
            before = len(tap.frames)
            c0 = clock()
            drives.write_targets(q[k])
            drives.sync()
            c1 = clock()
            rig.exchange()
            c2 = clock()
            drives.pump()
            drives.feedback()
            c3 = clock()
            cpu_ns.append((c1 - c0) + (c3 - c2))
            tap.drain(observer)
            per_tick.append(len(tap.frames) - before)
        frames = tap.frames
        heartbeat = [f for f in frames if 0x701 <= f[0] <= 0x77F]
        cyclic = len(frames) - len(heartbeat)
        bits = sum(frame_bits(cid, data) for cid, data in frames)
        worst = sum(worst_case_frame_bits(len(data)) for _, data in frames)
        duration_s = ticks * period_s
        load = bits / (duration_s * bitrate)
        load_worst = worst / (duration_s * bitrate)
        cpu_us = np.array(cpu_ns) / 1e3
        events = drives.poll_events()
    finally:
        observer.shutdown()
        drives.close()
        rig.close()
    return [
        f"frames per tick: cyclic {cyclic / ticks:.2f} (SYNC + 2 RPDO + 2 TPDO), with heartbeats "
        f"mean {len(frames) / ticks:.3f}, max {max(per_tick)} in one tick ({ticks} ticks)",
        f"bus load: {100 * load:.1f} % ({bits / ticks:.0f} bits/tick with exact stuffing; "
        f"worst-case stuffing {100 * load_worst:.1f} %)",
        f"master CPU per tick (write_targets+sync+pump+feedback, lockstep): mean "
        f"{cpu_us.mean():.1f} us, p99 {np.percentile(cpu_us, 99):.1f} us, max "
        f"{cpu_us.max():.1f} us",
        f"fault events during the run: {len(events)}",
    ]


def measure_latency(ticks: int, period_s: float, seed: int) -> list[str]:
    """Real time on python-can's virtual bus: SYNC on the bus -> last TPDO on the bus.

    A third bus on the channel observes the traffic; python-can's virtual bus stamps each
    frame when it is sent, so the figure is the rig's answer time, not the master's polling.
    The master runs as the daemon does: one tick per period, sleeping in between.
    """
    channel = f"tsmd-bench-latency-{os.getpid()}"
    drives, rig = open_sim_rig(_spring(), None, period_s, seed=seed,  # type: ignore[arg-type]
                               lockstep=False, channel=channel)
    observer = can.Bus(interface="virtual", channel=channel)
    frames: list[tuple[float, int]] = []
    try:
        drives.boot()
        drives.enable()
        while observer.recv(0) is not None:  # boot traffic
            pass
        q = _trajectory(ticks, period_s)
        next_t = time.perf_counter()
        for k in range(ticks):
            drives.write_targets(q[k])
            drives.sync()
            next_t += period_s
            time.sleep(max(0.0, next_t - time.perf_counter()))
            drives.pump()
            while (msg := observer.recv(0)) is not None:
                frames.append((msg.timestamp, msg.arbitration_id))
    finally:
        drives.close()
        rig.close()
        observer.shutdown()
    tpdo_ids = {0x180 + c.node_id for c in drives.configs}
    latencies: list[float] = []
    sync_t: float | None = None
    answered: set[int] = set()
    last_t = 0.0
    syncs = 0
    for t, cid in [*frames, (math.inf, 0x080)]:
        if cid == 0x080:
            if sync_t is not None and answered == tpdo_ids:
                latencies.append(last_t - sync_t)
            sync_t, answered = t, set()
            syncs += 1
        elif cid in tpdo_ids and sync_t is not None:
            answered.add(cid)
            last_t = t
    syncs -= 1  # the sentinel
    if not latencies:
        return ["SYNC-to-last-TPDO latency: no SYNC answered by both drives"]
    lat_us = np.array(latencies) * 1e6
    return [f"SYNC-to-last-TPDO latency (real time, virtual bus, rig thread; frame send "
            f"timestamps): median {statistics.median(lat_us):.0f} us, p99 "
            f"{np.percentile(lat_us, 99):.0f} us, max {lat_us.max():.0f} us over {syncs} SYNCs, "
            f"{syncs - len(latencies)} not answered by both drives before the next SYNC"]


def measure_speed(seconds: float, period_s: float, seed: int) -> list[str]:
    ticks = round(seconds / period_s)
    q = _trajectory(ticks, period_s)
    lines = []
    runs = [("spring stand-in plant", _spring(), "lockstep", ticks),
            ("tendon-sheath plant", load_plant(DEFAULT_PLANT), "lockstep", ticks),
            ("spring stand-in plant on python-can's virtual bus", _spring(), "virtual",
             min(ticks, 25000))]
    for label, plant, interface, n_ticks in runs:
        drives, rig = open_sim_rig(plant, None, period_s, seed=seed,  # type: ignore[arg-type]
                                   interface=interface)
        try:
            drives.boot()
            drives.enable()
            w0 = time.perf_counter()
            c0 = time.thread_time()
            for k in range(n_ticks):
                drives.write_targets(q[k])
                drives.sync()
                rig.exchange()
                drives.pump()
                drives.feedback()
            wall = time.perf_counter() - w0
            cpu = time.thread_time() - c0
        finally:
            drives.close()
            rig.close()
        sim_s = n_ticks * period_s
        lines.append(f"lockstep speed, {label}: {n_ticks} ticks ({sim_s:g} simulated s) in "
                     f"{wall:.2f} s wall = {sim_s / wall:.0f} simulated s per wall s "
                     f"({wall / n_ticks * 1e6:.1f} us/tick; CPU {cpu:.2f} s = "
                     f"{sim_s / cpu:.0f} simulated s per CPU s)")
    plant = load_plant(DEFAULT_PLANT)
    knob = np.zeros(2)
    n = min(ticks, 20000)
    w0 = time.perf_counter()
    c0 = time.thread_time()
    for k in range(n):
        knob[:] = q[k]
        plant.step(period_s, knob)
    lines.append(f"  of which the tendon-sheath plant.step alone: "
                 f"{(time.perf_counter() - w0) / n * 1e6:.1f} us/tick wall, "
                 f"{(time.thread_time() - c0) / n * 1e6:.1f} us/tick CPU")
    return lines


class _TimedPlant:
    """Wraps a plant and adds up the wall time of its ``step`` calls (the plant's share)."""

    def __init__(self, plant: Plant) -> None:
        self.plant = plant
        self.step_s = 0.0

    def reset(self) -> None:
        self.plant.reset()

    def step(self, dt_s: float, knob_deg: np.ndarray) -> object:
        t0 = time.perf_counter()
        answer = self.plant.step(dt_s, knob_deg)
        self.step_s += time.perf_counter() - t0
        return answer


def measure_stack(seconds: float, seed: int) -> list[str]:
    """The whole stack as ``tsmd calibrate --sim`` runs it (LockstepRunner: control loop with
    limiter, CANopen master, lockstep bus, simulated drives, motors, sensors, tracker), once with
    a null plant and once with the tendon-sheath plant, in one process: stack vs plant per tick.
    """
    lines = []
    plants = [("null plant (spring stand-in)", _spring()),
              ("tendon-sheath plant", load_plant(DEFAULT_PLANT))]
    for label, plant in plants:
        timed = _TimedPlant(plant)  # type: ignore[arg-type]
        with LockstepRunner(plant=timed, seed=seed) as runner:  # type: ignore[arg-type]
            period_s = runner.period_s
            ticks = round(seconds / period_s)
            t = np.arange(ticks) * period_s
            q = _trajectory(ticks, period_s)
            timed.step_s = 0.0
            w0 = time.perf_counter()
            c0 = time.thread_time()
            runner.run(t, q, compensate=False)
            wall = time.perf_counter() - w0
            cpu = time.thread_time() - c0
        per_tick_us = wall / ticks * 1e6
        plant_us = timed.step_s / ticks * 1e6
        lines.append(f"whole stack, {label}: {ticks} ticks in {wall:.2f} s wall = "
                     f"{ticks / wall:.0f} ticks/s ({per_tick_us:.1f} us/tick: plant.step "
                     f"{plant_us:.1f}, stack {per_tick_us - plant_us:.1f}); CPU {cpu:.2f} s = "
                     f"{ticks / cpu:.0f} ticks per CPU s ({cpu / ticks * 1e6:.1f} us/tick)")
        if label.startswith("tendon"):
            sweep_ticks = round(850.0 / period_s)
            lines.append(f"  the paper protocol with 3 re-sweeps (850 s, {sweep_ticks} ticks) at "
                         f"this rate: {sweep_ticks * per_tick_us * 1e-6:.0f} s wall of ticking, "
                         f"of which plant {sweep_ticks * plant_us * 1e-6:.0f} s")
    return lines
