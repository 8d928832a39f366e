"""The daemon process: start-up, systemd notification, SIGTERM mid-motion, bad config."""

from __future__ import annotations

import dataclasses
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import can
import numpy as np
import pytest
import yaml

from tsmd import daemon_drives
from tsmd.api.client import ApiClient
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.daemon import Daemon, resolve_socket_path
from tsmd.log import get_logger
from tsmd.notify import Notifier, watchdog_interval_s
from tsmd.recording import read_recording
from tsmd.replay import LiveTrajectoryRunner

SIM_YAML = Path(__file__).resolve().parent.parent / "tsmd" / "data" / "sim.yaml"


def sim_config(tmp_path: Path, **recording: object) -> Path:
    data = yaml.safe_load(SIM_YAML.read_text())
    data["recording"] = {"enabled": True, "dir": str(tmp_path / "rec"),
                         "flush_interval_s": 0.2, **recording}
    path = tmp_path / "tsmd.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def notify_socket(tmp_path: Path) -> socket.socket:
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind(str(tmp_path / "notify.sock"))
    sock.settimeout(30.0)
    return sock


def read_notifications(sock: socket.socket, until: str, timeout_s: float = 30.0) -> list[str]:
    seen: list[str] = []
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        seen.extend(sock.recv(4096).decode().splitlines())
        if until in seen:
            return seen
    raise AssertionError(f"no {until} in {seen}")


def test_sigterm_mid_motion_stops_disables_flushes_and_exits_0(tmp_path: Path) -> None:
    notify = notify_socket(tmp_path)
    sock_path = tmp_path / "tsmd.sock"
    env = dict(os.environ, NOTIFY_SOCKET=str(tmp_path / "notify.sock"), WATCHDOG_USEC="2000000")
    proc = subprocess.Popen(
        [sys.executable, "-m", "tsmd", "run", "--sim", "--config", str(sim_config(tmp_path)),
         "--socket", str(sock_path), "--log-format", "json", "--demo"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path, env=env)
    try:
        seen = read_notifications(notify, "READY=1")
        with ApiClient(sock_path) as client:
            deadline = time.monotonic() + 20
            moving = False
            while time.monotonic() < deadline and not moving:
                sample = client.call("get")["sample"]
                moving = sample["state"] == "ENABLED" and abs(sample["pos"][0]) > 5.0
                time.sleep(0.05)
            assert moving, sample
        seen += read_notifications(notify, "WATCHDOG=1")
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, err
    assert "final state DISABLED" in out
    assert "shutdown: drives quick-stopped and disabled" in err
    assert any(line.startswith("STATUS=") for line in seen)
    assert not sock_path.exists()
    recordings = list((tmp_path / "rec").glob("*.csv"))
    assert len(recordings) == 1
    rec = read_recording(recordings[0])
    assert len(rec) > 100
    assert abs(rec["pos1"]).max() > 5.0
    assert rec.metadata["sim"] == "True"


def test_run_sim_with_duration_exits_0_with_a_summary(tmp_path: Path) -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "tsmd", "run", "--sim", "--duration", "3", "--socket",
         str(tmp_path / "s.sock")], capture_output=True, text=True, timeout=60, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "ticks at 250 Hz" in proc.stdout
    assert "demo, compensation none" in proc.stdout
    assert "simulated rig: " in proc.stdout


def test_bad_config_is_refused_with_key_and_reason(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("loop:\n  rate_hz: 5000\n")
    proc = subprocess.run([sys.executable, "-m", "tsmd", "run", "--config", str(bad)],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert "loop.rate_hz" in proc.stderr and "out of range" in proc.stderr
    assert "Traceback" not in proc.stderr


def test_socket_falls_back_when_its_directory_cannot_be_used(tmp_path: Path,
                                                             monkeypatch: pytest.MonkeyPatch
                                                             ) -> None:
    monkeypatch.delenv("RUNTIME_DIRECTORY", raising=False)
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(tmp_path))
    blocker = tmp_path / "file"
    blocker.write_text("")
    path, warning = resolve_socket_path(str(blocker / "tsmd" / "tsmd.sock"))
    assert path == tmp_path / f"tsmd-{os.getuid()}" / "tsmd.sock"
    assert warning is not None and "instead" in warning


def test_runtime_directory_from_systemd_holds_the_socket(tmp_path: Path,
                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("RUNTIME_DIRECTORY", str(tmp_path))
    assert resolve_socket_path("/run/tsmd/tsmd.sock") == (tmp_path / "tsmd.sock", None)


def test_notifier_sends_datagrams_to_the_abstract_or_path_socket(tmp_path: Path) -> None:
    sock = notify_socket(tmp_path)
    notifier = Notifier(str(tmp_path / "notify.sock"))
    assert notifier.ready(status="up")
    assert sock.recv(100) == b"READY=1\nSTATUS=up"
    assert notifier.watchdog()
    assert sock.recv(100) == b"WATCHDOG=1"
    abstract = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    abstract.bind(f"\0tsmd-test-{os.getpid()}")
    assert Notifier(f"@tsmd-test-{os.getpid()}").stopping()
    assert abstract.recv(100) == b"STOPPING=1"


def test_notifier_without_notify_socket_is_a_no_op(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("NOTIFY_SOCKET", raising=False)
    notifier = Notifier()
    assert not notifier.enabled
    assert notifier.ready() is False


def test_watchdog_interval_is_half_of_watchdog_usec(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("WATCHDOG_USEC", "3000000")
    monkeypatch.delenv("WATCHDOG_PID", raising=False)
    assert watchdog_interval_s() == pytest.approx(1.5)
    monkeypatch.setenv("WATCHDOG_PID", "1")
    assert watchdog_interval_s() is None


def test_calibrate_over_the_socket_streams_progress_and_cancel_saves_nothing(
        tmp_path: Path) -> None:
    base = default_sim_config()
    config = dataclasses.replace(base, profiles=dataclasses.replace(
        base.profiles, dir=str(tmp_path / "profiles"), active=None))
    daemon = Daemon(config, sim=True, socket_path=str(tmp_path / "d.sock"))
    daemon.start()
    try:
        with ApiClient(tmp_path / "d.sock") as client, ApiClient(tmp_path / "d.sock") as other:
            client.send_raw(b'{"id": "cal", "cmd": "calibrate", "catheter": "cath-7"}\n')
            first = client.read_message()
            assert first["id"] == "cal" and first["event"] == "progress", first
            assert other.call("cancel")["cancelled"] is True
            response = client.read_message()
            while "event" in response:
                response = client.read_message()
            assert response["id"] == "cal"
            assert response["error"]["code"] == "cancelled"
            assert other.call("status")["state"] == "ENABLED"
            # a client that disconnects mid-calibration cancels it too
            gone = ApiClient(tmp_path / "d.sock")
            gone.send_raw(b'{"id": 1, "cmd": "calibrate", "catheter": "cath-8"}\n')
            assert gone.read_message()["event"] == "progress"
            gone.close()
            deadline = time.monotonic() + 20
            while other.call("status")["calibrating"] and time.monotonic() < deadline:
                time.sleep(0.1)
            assert other.call("status")["calibrating"] is False
    finally:
        daemon.stop()
    assert not (tmp_path / "profiles" / "cath-7.yaml").exists()
    assert not (tmp_path / "profiles" / "cath-8.yaml").exists()


@pytest.mark.parametrize("fmt", ["blf", "asc"])
def test_can_traffic_is_logged_with_python_cans_own_writer(tmp_path: Path, fmt: str) -> None:
    base = TsmdConfig()
    config = dataclasses.replace(
        base, bus=dataclasses.replace(base.bus, log_format=fmt),  # type: ignore[arg-type]
        recording=dataclasses.replace(base.recording, dir=str(tmp_path)))
    channel = f"tsmd-canlog-{os.getpid()}-{fmt}"
    bus = can.Bus(interface="virtual", channel=channel)
    peer = can.Bus(interface="virtual", channel=channel)
    logged = daemon_drives.can_log(config, bus, get_logger("tsmd.test"))
    try:
        logged.send(can.Message(arbitration_id=0x080, data=b"", is_extended_id=False))
        peer.send(can.Message(arbitration_id=0x181, data=b"\x27\x00", is_extended_id=False))
        assert logged.recv(1.0) is not None
    finally:
        logged.shutdown()  # stops the writer, then the bus it wraps
        peer.shutdown()
    (log,) = tmp_path.glob(f"tsmd-can-*.{fmt}")
    ids = [m.arbitration_id for m in can.LogReader(str(log))]
    assert ids == [0x080, 0x181]


def test_live_runner_plays_a_trajectory_on_the_running_daemon(tmp_path: Path) -> None:
    base = default_sim_config()
    config = dataclasses.replace(base, profiles=dataclasses.replace(base.profiles, active=None))
    daemon = Daemon(config, sim=True, api=False)
    daemon.start()
    try:
        assert daemon.loop is not None
        daemon.loop.post("enable").result(timeout=10)
        t = np.linspace(0.0, 1.0, 11)
        q = np.column_stack([20.0 * t, -10.0 * t])
        fractions: list[float] = []
        rec = LiveTrajectoryRunner(daemon.loop, poll_s=0.05).run(t, q, compensate=False,
                                                                progress=fractions.append)
    finally:
        daemon.stop()
    assert len(rec) == 251
    assert rec["q1"][-1] == pytest.approx(20.0)
    assert rec["pos1"][-1] == pytest.approx(20.0, abs=1.5)
    assert fractions and fractions == sorted(fractions)


def test_sigint_stops_cleanly_too(tmp_path: Path) -> None:
    notify = notify_socket(tmp_path)
    env = dict(os.environ, NOTIFY_SOCKET=str(tmp_path / "notify.sock"))
    proc = subprocess.Popen(
        [sys.executable, "-m", "tsmd", "run", "--sim", "--no-demo", "--socket",
         str(tmp_path / "s.sock")], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env=env, cwd=tmp_path)
    try:
        read_notifications(notify, "READY=1")
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, err
    assert "final state DISABLED" in out


def test_injected_drive_fault_shows_on_the_api_and_reset_waits_for_the_cause(
        tmp_path: Path) -> None:
    base = default_sim_config()
    config = dataclasses.replace(base, profiles=dataclasses.replace(base.profiles, active=None))
    daemon = Daemon(config, sim=True, socket_path=str(tmp_path / "f.sock"))
    daemon.start()
    try:
        with ApiClient(tmp_path / "f.sock") as c:
            c.call("enable")
            c.call("set", q=[20.0, 0.0])
            daemon.rig.inject_fault("heartbeat_stop", drive=1)
            deadline = time.monotonic() + 5
            status = c.call("status")
            while status["state"] != "FAULT" and time.monotonic() < deadline:
                time.sleep(0.05)
                status = c.call("status")
            assert status["state"] == "FAULT"
            assert "heartbeat" in status["fault"]
            assert c.request("set", q=[0.0, 0.0])["error"]["code"] == "not_enabled"
            refused = c.request("reset")
            assert refused["ok"] is False and refused["error"]["code"] == "fault", refused
            daemon.rig.clear_fault(1)
            time.sleep(0.3)
            assert c.call("reset")["state"] == "DISABLED"
            assert c.call("enable")["state"] == "ENABLED"
    finally:
        daemon.stop()


BAD_FILES = {
    "not_utf8": b"catheter_id: x\n# \xff\xfe\n",
    "deep": b"a: " + b"[" * 500 + b"]" * 500 + b"\n",
    "truncated": b"catheter_id: cath-1\nknobs:\n  - omega: 1.0\n    reference_pos: {knob_deg: 3",
}


@pytest.mark.parametrize("which", ["profile", "config"])
@pytest.mark.parametrize("kind", sorted(BAD_FILES))
def test_a_bad_profile_or_config_file_is_one_line_naming_it(tmp_path: Path, which: str,
                                                            kind: str) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_bytes(BAD_FILES[kind])
    config = bad if which == "config" else sim_config(tmp_path)
    args = [sys.executable, "-m", "tsmd", "run", "--sim", "--no-demo", "--duration", "0.1",
            "--socket", str(tmp_path / "d.sock"), "--config", str(config)]
    if which == "profile":
        args += ["--profile", str(bad)]
    proc = subprocess.run(args, capture_output=True, text=True, timeout=60)
    assert proc.returncode != 0
    assert "Traceback" not in proc.stderr
    errors = [line for line in proc.stderr.splitlines() if "error" in line]
    assert len(errors) == 1 and str(bad) in errors[0], proc.stderr
