"""`tsmd bench NAME`: benchmarks that print figures; one module per benchmark in tsmd.bench."""

from __future__ import annotations

import argparse
from types import ModuleType

from tsmd.bench import (
    accuracy,
    bus,
    calibration,
    compute,
    family_accuracy,
    gap,
    loop,
    online,
    realism,
)

BENCHMARKS: dict[str, tuple[ModuleType, str]] = {
    "bus": (bus, "CAN frames, bus load, CPU and latency per tick"),
    "loop": (loop, "control-loop lateness, jitter, overruns; cyclictest beside it"),
    "accuracy": (accuracy, "the paper's tracking protocol: none / paper / ours"),
    "compute": (compute, "the compensator's cost per tick, normal scheduler and SCHED_FIFO"),
    "calibration": (calibration, "identified D and B against ground truth"),
    "gap": (gap, "sim-to-real gap diagnosis self-test and speed"),
    "family": (family_accuracy, "tracking on catheter units each calibrated from current"),
    "online": (online, "online dead-zone re-estimation through a shape change"),
    "realism": (realism, "family of simulated catheters against the paper's figures"),
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="benchmark", metavar="BENCHMARK", required=True)
    for name, (module, help_text) in BENCHMARKS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        module.add_arguments(p)
        p.set_defaults(_bench=module)


def main(args: argparse.Namespace) -> int:
    if args._bench is accuracy and accuracy.wants_family(args):
        return int(family_accuracy.main(family_accuracy.namespace_from(args)))
    return int(args._bench.main(args))
