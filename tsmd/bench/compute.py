"""`tsmd bench compute`: the compensator's cost per tick for saved profiles, as the loop runs it.

`tsmd bench family` prints the cost of one tick under the normal scheduler, where a shared
machine's other processes preempt the timing loop and its p99 measures the machine's load as
much as the code. The daemon's loop thread runs at SCHED_FIFO (``loop.realtime.priority``,
default 80), where ordinary processes cannot preempt it, with everything built before the
loop frozen out of the garbage collector (``gc.freeze``). This bench times the same ticks both
ways, one run after the other on the same profile, so the two can be compared.
"""

from __future__ import annotations

import argparse
import gc
import os
from pathlib import Path

from tsmd.bench.accuracy import compute_time_us
from tsmd.errors import TsmdError
from tsmd.profile import load_profile
from tsmd.rt import fifo_scheduling

DAEMON_PRIORITY = 80
"""The loop thread's SCHED_FIFO priority in the daemon's default configuration."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("profiles", nargs="+", type=Path,
                        help="catheter profiles (e.g. the unit-<n>.yaml files `tsmd bench "
                             "family --profiles DIR` keeps)")
    parser.add_argument("--method", default="ours", choices=("none", "paper", "ours"))
    parser.add_argument("--ticks", type=int, default=5000, help="ticks timed per measurement")
    parser.add_argument("--fifo-priority", type=int, default=DAEMON_PRIORITY,
                        help="SCHED_FIFO priority of the second measurement (1-99; the "
                             "daemon's loop default is 80)")


def _row(label: str, fifo: str, profile: object, method: str, ticks: int) -> str:
    wall = compute_time_us(profile, method, n_ticks=ticks)
    cpu = compute_time_us(profile, method, n_ticks=ticks, clock="cpu")
    plan = compute_time_us(profile, method, n_ticks=ticks, planned=True)
    return (f"| {label} | {fifo} | {wall[0]:.1f} / {wall[1]:.1f} | {cpu[0]:.1f} / {cpu[1]:.1f} "
            f"| {plan[0]:.1f} / {plan[1]:.1f} |")


def main(args: argparse.Namespace) -> int:
    if not 1 <= args.fifo_priority <= 99:
        raise TsmdError(f"--fifo-priority {args.fifo_priority} is outside 1-99")
    if args.ticks < 100:
        raise TsmdError(f"--ticks {args.ticks} is too few for a p99 (at least 100)")
    loaded = [(path, load_profile(path)) for path in args.profiles]
    print(f"load average {os.getloadavg()[0]:.1f}; {args.ticks} ticks per cell; method "
          f"{args.method}; median / p99 us, two knobs", flush=True)
    print("| profile | scheduler | wall | CPU | wall, playing a trajectory |")
    print("|---|---|---|---|---|")
    refusals: list[str] = []
    for path, profile in loaded:
        print(_row(path.name, "normal", profile, args.method, args.ticks), flush=True)
        with fifo_scheduling(args.fifo_priority) as refused:
            if refused is None:
                gc.collect()
                gc.freeze()
                try:
                    print(_row(path.name, f"as the loop: SCHED_FIFO {args.fifo_priority}, "
                               "gc frozen", profile, args.method, args.ticks), flush=True)
                finally:
                    gc.unfreeze()
            else:
                refusals.append(refused)
    if refusals:
        print(f"not measured under SCHED_FIFO: {refusals[0]}")
        return 1
    return 0
