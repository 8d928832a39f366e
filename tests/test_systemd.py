"""The systemd unit: it verifies, it asks for what the daemon needs, and it is hardened."""

from __future__ import annotations

import configparser
import re
import shutil
import subprocess
import sys
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


def installed_copy(tmp_path: Path) -> Path:
    """The unit with ExecStart pointing at this machine's tsmd (verify checks the binary)."""
    exe = shutil.which("tsmd") or sys.executable
    text = UNIT.read_text()
    if not Path("/usr/local/bin/tsmd").exists():
        text = text.replace("/usr/local/bin/tsmd", exe)
    copy = tmp_path / "tsmd.service"
    copy.write_text(text)
    return copy


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
