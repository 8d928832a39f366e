"""The command line: help works and user errors are one line, never a traceback."""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import pytest

from tsmd.cli import main
from tsmd.commands import run as run_command
from tsmd.config import default_sim_config


def test_help_lists_every_command(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    for name in ("run", "sim", "calibrate", "replay", "gap", "bench"):
        assert name in out


def test_every_command_has_help(capsys: pytest.CaptureFixture[str]) -> None:
    for name in ("run", "sim", "calibrate", "datasheet", "replay", "gap", "bench"):
        with pytest.raises(SystemExit) as exc:
            main([name, "--help"])
        assert exc.value.code == 0
        assert capsys.readouterr().out.startswith(f"usage: tsmd {name}")


def test_a_config_without_drives_is_one_line_naming_drives(tmp_path: Path) -> None:
    config = tmp_path / "empty.yaml"
    config.write_text("", encoding="utf-8")
    # a process of its own: `tsmd run` configures the process's logging
    proc = subprocess.run([sys.executable, "-m", "tsmd", "run", "--sim", "--no-demo",
                           "--duration", "0.1", "--config", str(config),
                           "--socket", str(tmp_path / "t.sock")],
                          capture_output=True, text=True, timeout=60)
    lines = [line for line in proc.stderr.splitlines()
             if not line.startswith("{")]  # the event log's JSON lines go to stderr too
    assert proc.returncode == 2
    assert len(lines) == 1 and "drives: expected 2 drives" in lines[0], proc.stderr


def test_an_unknown_option_is_refused_with_the_commands_own_usage(
        capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["calibrate", "--catheter", "x", "--out", "p.yaml"])
    err = capsys.readouterr().err
    assert exc.value.code == 2
    assert err.startswith("usage: tsmd calibrate")
    assert "tsmd calibrate: error: unrecognized arguments: --out p.yaml" in err


@pytest.mark.parametrize("duration", ["-1", "0", "nan", "inf"])
def test_run_refuses_a_duration_that_is_not_a_positive_time(
        duration: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "--sim", "--duration", duration]) == 2
    assert "--duration must be a positive number of seconds" in capsys.readouterr().err


@pytest.mark.parametrize("priority", ["-1", "100"])
def test_run_refuses_a_realtime_priority_outside_0_to_99(
        priority: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "--sim", "--realtime-priority", priority]) == 2
    assert "--realtime-priority must be 0-99" in capsys.readouterr().err


def test_run_realtime_priority_overrides_the_configured_one() -> None:
    args = argparse.Namespace(config=None, sim=True, realtime_priority=80)
    assert default_sim_config().loop.realtime.priority == 0
    assert run_command._config(args).loop.realtime.priority == 80
