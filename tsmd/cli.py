"""The ``tsmd`` command: a thin dispatcher onto one module per subcommand.

Each command module under :mod:`tsmd.commands` provides ``add_arguments(parser)`` and
``main(args) -> int``. Errors meant for the user become one line on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from types import ModuleType

from drivers.drive import DriveError
from simrig.plant import PlantLoadError, PlantOutputError
from tsmd import __version__
from tsmd.commands import bench, calibrate, datasheet, gap, replay, run, sim
from tsmd.errors import TsmdError

COMMANDS: dict[str, tuple[ModuleType, str]] = {
    "run": (run, "run the daemon (loop, drives, socket API)"),
    "sim": (sim, "run the simulated rig as its own process on a CAN interface"),
    "calibrate": (calibrate, "calibrate a catheter from motor current"),
    "datasheet": (datasheet, "measure a device's data sheet (simulator or tracked recordings)"),
    "replay": (replay, "run a trajectory through the full stack and record it"),
    "gap": (gap, "diagnose the sim-to-real gap from real recordings"),
    "bench": (bench, "benchmarks that print figures (bus, loop, accuracy, ...)"),
}

USER_ERRORS: tuple[type[BaseException], ...] = (TsmdError, DriveError, PlantLoadError,
                                                PlantOutputError)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="tsmd", description="Driver daemon for tendon-sheath-driven robotic catheters.")
    parser.add_argument("--version", action="version", version=_version())
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, (module, help_text) in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=help_text)
        module.add_arguments(p)
        p.set_defaults(_module=module, _parser=p)
    return parser


def _version() -> str:
    return f"tsmd {__version__}"


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args, unknown = parser.parse_known_args(argv)
    if unknown:  # the command's own usage, not the top level's
        args._parser.error(f"unrecognized arguments: {' '.join(unknown)}")
    try:
        return int(args._module.main(args))
    except USER_ERRORS as exc:
        print(f"tsmd {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"tsmd {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
