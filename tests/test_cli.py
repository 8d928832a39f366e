"""The command line: help works and user errors are one line, never a traceback."""

from __future__ import annotations

import pytest

from tsmd.cli import main


def test_help_lists_every_command(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    for name in ("run", "sim", "calibrate", "replay", "gap", "bench"):
        assert name in out
