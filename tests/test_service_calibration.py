"""A calibration on the live daemon: it never outlives its client, and cancel/stop reach it."""

from __future__ import annotations

import dataclasses
import json
import socket
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tsmd.api.client import ApiClient
from tsmd.config import default_sim_config
from tsmd.daemon import Daemon

CALIBRATE = b'{"id": "c", "cmd": "calibrate", "catheter": "cath-y"}\n'


@pytest.fixture
def daemon(tmp_path: Path) -> Iterator[Daemon]:
    base = default_sim_config()
    config = dataclasses.replace(base, profiles=dataclasses.replace(
        base.profiles, dir=str(tmp_path / "profiles"), active=None))
    d = Daemon(config, sim=True, socket_path=str(tmp_path / "d.sock"))
    d.start()
    yield d
    d.stop()


def raw_calibrate(path: Path) -> socket.socket:
    """A bare socket that starts a calibration and waits for its first progress event."""
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.settimeout(20.0)
    sock.connect(str(path))
    sock.sendall(CALIBRATE)
    first = json.loads(sock.makefile("rb").readline())
    assert first.get("event") == "progress", first
    return sock


def wait_until_idle(client: ApiClient, timeout_s: float = 30.0) -> dict[str, Any]:
    deadline = time.monotonic() + timeout_s
    status = client.call("status")
    while status["calibrating"] and time.monotonic() < deadline:
        time.sleep(0.1)
        status = client.call("status")
    return status


def test_a_client_closing_abruptly_ends_its_calibration_knobs_to_zero_nothing_saved(
        daemon: Daemon, tmp_path: Path) -> None:
    # The black-box probe: calibrate on a raw socket, read nothing, close after 3 s. The unread
    # progress lines make the close a reset (ECONNRESET on the daemon's side).
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.connect(str(tmp_path / "d.sock"))
    sock.sendall(CALIBRATE)
    time.sleep(3.0)
    sock.close()
    with ApiClient(tmp_path / "d.sock") as other:
        status = wait_until_idle(other)
        assert status["calibrating"] is False
        assert other.call("cancel")["cancelled"] is False
        position = status["sample"]["pos"]
        assert all(abs(p) < 2.0 for p in position), position
        time.sleep(1.0)  # nothing moves on its own afterwards
        later = other.call("status")["sample"]["pos"]
        assert all(abs(a - b) < 0.5 for a, b in zip(position, later, strict=True)), later
    assert not (tmp_path / "profiles" / "cath-y.yaml").exists()


def test_a_client_closing_after_reading_progress_ends_its_calibration(
        daemon: Daemon, tmp_path: Path) -> None:
    sock = raw_calibrate(tmp_path / "d.sock")
    sock.close()
    with ApiClient(tmp_path / "d.sock") as other:
        assert wait_until_idle(other)["calibrating"] is False
    assert not (tmp_path / "profiles" / "cath-y.yaml").exists()


def test_status_says_calibrating_while_one_runs_and_a_second_calibrate_is_busy(
        daemon: Daemon, tmp_path: Path) -> None:
    with ApiClient(tmp_path / "d.sock") as client, ApiClient(tmp_path / "d.sock") as other:
        client.send_raw(CALIBRATE)
        assert client.read_message()["event"] == "progress"
        assert other.call("status")["calibrating"] is True
        second = other.request("calibrate", catheter="cath-z")
        assert second["error"]["code"] == "busy", second
        assert other.call("status")["calibrating"] is True
        assert other.call("cancel")["cancelled"] is True
        assert wait_until_idle(other)["calibrating"] is False


def test_stop_during_calibration_reports_the_cancel_not_the_stopped_loop(
        daemon: Daemon, tmp_path: Path) -> None:
    with ApiClient(tmp_path / "d.sock") as client, ApiClient(tmp_path / "d.sock") as other:
        client.send_raw(CALIBRATE)
        assert client.read_message()["event"] == "progress"
        other.call("stop")
        response = client.read_message()
        while "event" in response:
            response = client.read_message()
        assert response["error"]["code"] == "cancelled", response
        assert "DISABLED" not in response["error"]["message"]
        assert wait_until_idle(other)["calibrating"] is False
    assert not (tmp_path / "profiles" / "cath-y.yaml").exists()


def test_shutdown_during_calibration_cancels_it_and_logs_the_cancel(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    base = default_sim_config()
    config = dataclasses.replace(base, profiles=dataclasses.replace(
        base.profiles, dir=str(tmp_path / "profiles"), active=None))
    d = Daemon(config, sim=True, socket_path=str(tmp_path / "d.sock"))
    d.start()
    try:
        with ApiClient(tmp_path / "d.sock") as client:
            client.send_raw(CALIBRATE)
            assert client.read_message()["event"] == "progress"
            assert d.service is not None
            d.stop()
            assert d.service.calibrating is False
    finally:
        d.stop()
    text = capsys.readouterr().out
    assert "calibration started" in text
    assert "calibration cancelled" in text
    assert "cannot play a trajectory" not in text
    assert not (tmp_path / "profiles" / "cath-y.yaml").exists()
