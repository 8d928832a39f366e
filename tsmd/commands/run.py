"""`tsmd run`: not built yet (see the open issue)."""

from __future__ import annotations

import argparse

from tsmd.errors import TsmdError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("rest", nargs=argparse.REMAINDER)


def main(args: argparse.Namespace) -> int:
    raise TsmdError("'tsmd run' is not implemented yet")
