"""The systemd unit: it verifies, it asks for what the daemon needs, and it is hardened."""

from __future__ import annotations

import configparser
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

UNIT = Path(__file__).resolve().parent.parent / "systemd" / "tsmd.service"


def unit_values() -> dict[str, list[str]]:
    values: dict[str, list[str]] = {}
    section = ""
    for raw in UNIT.read_text().splitlines():
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith("["):
            section = line.strip("[]")
            continue
        key, _, value = line.partition("=")
        values.setdefault(f"{section}.{key}", []).append(value)
    return values


SHIPPED_EXEC = "/usr/local/bin/tsmd"
"""Where the unit expects the console script (pip install as root); docs/configuration.md."""


def installed_copy(tmp_path: Path) -> Path:
    """The unit with ExecStart pointing at this machine's installed tsmd (verify checks it)."""
    exe = shutil.which("tsmd")
    if exe is None:
        pytest.skip("no tsmd console script on PATH: the unit's ExecStart cannot be checked")
    copy = tmp_path / "tsmd.service"
    copy.write_text(UNIT.read_text().replace(SHIPPED_EXEC, str(Path(exe).resolve())))
    return copy


def test_the_shipped_unit_runs_the_documented_tsmd_path() -> None:
    exec_start = unit_values()["Service.ExecStart"][0]
    assert exec_start.split()[0] == SHIPPED_EXEC
    docs = (UNIT.parent.parent / "docs" / "configuration.md").read_text()
    assert SHIPPED_EXEC in docs


def test_the_verified_copy_runs_the_installed_tsmd(tmp_path: Path) -> None:
    copy = installed_copy(tmp_path)
    exec_start = next(line for line in copy.read_text().splitlines()
                      if line.startswith("ExecStart="))
    binary = Path(exec_start.removeprefix("ExecStart=").split()[0])
    assert binary.is_file() and os.access(binary, os.X_OK)
    assert exec_start.endswith("run --config /etc/tsmd/tsmd.yaml --log-format json")


def test_unit_is_type_notify_with_watchdog_restart_and_directories() -> None:
    v = unit_values()
    assert v["Service.Type"] == ["notify"]
    assert v["Service.WatchdogSec"]
    assert v["Service.Restart"] == ["on-failure"]
    assert v["Service.RuntimeDirectory"] == ["tsmd"]
    assert v["Service.StateDirectory"] == ["tsmd"]
    assert v["Service.LimitRTPRIO"] and v["Service.LimitMEMLOCK"] == ["infinity"]
    assert "run" in v["Service.ExecStart"][0]


def test_hardening_still_allows_can_unix_and_netlink_sockets_and_realtime() -> None:
    v = unit_values()
    assert set(v["Service.RestrictAddressFamilies"][0].split()) == {"AF_UNIX", "AF_CAN",
                                                                    "AF_NETLINK"}
    assert v["Service.PrivateNetwork"] == ["no"]
    assert v["Service.RestrictRealtime"] == ["no"]
    assert "sched_setscheduler" in " ".join(v["Service.SystemCallFilter"])
    assert v["Service.NoNewPrivileges"] == ["yes"]


def test_systemd_analyze_verify_passes(tmp_path: Path) -> None:
    tool = shutil.which("systemd-analyze")
    if tool is None:
        pytest.skip("systemd-analyze is not installed")
    proc = subprocess.run([tool, "verify", str(installed_copy(tmp_path))], capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr


def test_security_exposure_stays_low(tmp_path: Path) -> None:
    tool = shutil.which("systemd-analyze")
    if tool is None:
        pytest.skip("systemd-analyze is not installed")
    proc = subprocess.run([tool, "security", "--offline=true", str(installed_copy(tmp_path))],
                          capture_output=True, text=True, timeout=60)
    match = re.search(r"Overall exposure level for tsmd.service: ([0-9.]+)", proc.stdout)
    if match is None:
        pytest.skip(f"this systemd-analyze cannot assess unit files offline: {proc.stderr[:200]}")
    assert float(match.group(1)) <= 1.5


def test_unit_file_parses_as_ini() -> None:
    parser = configparser.ConfigParser(strict=False, interpolation=None)
    parser.read_string(UNIT.read_text())
    assert {"Unit", "Service", "Install"} <= set(parser.sections())
