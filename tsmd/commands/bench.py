"""`tsmd bench NAME`: benchmarks that print figures; one module per benchmark in tsmd.bench."""

from __future__ import annotations

import argparse
import importlib

BENCHMARKS: dict[str, tuple[str, str]] = {
    "bus": ("tsmd.bench.bus", "CAN frames, bus load, CPU and latency per tick"),
    "loop": ("tsmd.bench.loop", "control-loop lateness, jitter, overruns; cyclictest beside it"),
    "accuracy": ("tsmd.bench.accuracy", "the paper's tracking protocol: none / paper / ours"),
    "calibration": ("tsmd.bench.calibration", "identified D and B against ground truth"),
    "gap": ("tsmd.bench.gap", "sim-to-real gap diagnosis self-test and speed"),
    "online": ("tsmd.bench.online", "online dead-zone re-estimation through a shape change"),
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    sub = parser.add_subparsers(dest="benchmark", metavar="BENCHMARK", required=True)
    for name, (module_name, help_text) in BENCHMARKS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError:
            p.set_defaults(_bench=None)
            continue
        module.add_arguments(p)
        p.set_defaults(_bench=module)


def main(args: argparse.Namespace) -> int:
    from tsmd.errors import TsmdError

    if args._bench is None:
        raise TsmdError(f"benchmark {args.benchmark!r} is not implemented yet")
    return int(args._bench.main(args))
