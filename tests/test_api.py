"""The socket API: every command, every error, and clients that misbehave."""

from __future__ import annotations

import json
import os
import shutil
import socket
import stat
import subprocess
import time
from pathlib import Path

import pytest
from support.api import Stack, all_targets_inside_limits, start_stack

from tsmd.api.client import ApiClient, ApiClientError
from tsmd.api.protocol import Request, ok
from tsmd.api.server import ApiServer, ApiServerError
from tsmd.loop import LoopState


def error_code(response: dict[str, object]) -> str:
    assert response["ok"] is False, response
    err = response["error"]
    assert isinstance(err, dict) and err["message"]
    return str(err["code"])


def raw(client: ApiClient, line: bytes) -> dict[str, object]:
    client.send_raw(line + b"\n")
    return client.read_message()


# --- the socket ------------------------------------------------------------------------------

def test_socket_has_mode_0660(stack: Stack) -> None:
    assert stat.S_IMODE(os.stat(stack.path).st_mode) == 0o660


def test_a_regular_file_at_the_socket_path_is_not_replaced(tmp_path: Path) -> None:
    path = tmp_path / "tsmd.sock"
    path.write_text("precious")

    async def handler(*_: object) -> dict[str, object]:
        return {}

    with pytest.raises(ApiServerError, match="not a socket"):
        ApiServer(path, handler).start()
    assert path.read_text() == "precious"


# --- every command ---------------------------------------------------------------------------

def test_status_reports_state_rate_and_counters(stack: Stack) -> None:
    with stack.client() as c:
        r = c.call("status")
    assert r["state"] == "DISABLED"
    assert r["rate_hz"] == pytest.approx(250.0)
    assert r["ticks"] > 0 and r["overruns"] >= 0
    assert r["compensation"]["active"] == "none"


def test_id_is_echoed_whatever_its_type(stack: Stack) -> None:
    with stack.client() as c:
        assert raw(c, b'{"id": "abc", "cmd": "status"}')["id"] == "abc"
        assert raw(c, b'{"id": 42, "cmd": "status"}')["id"] == 42
        assert raw(c, b'{"cmd": "status"}')["id"] is None


def test_enable_set_get_moves_the_knobs(stack: Stack) -> None:
    with stack.client() as c:
        assert c.call("enable")["state"] == "ENABLED"
        assert c.call("set", q=[20.0, -10.5])["q"] == [20.0, -10.5]
        deadline = time.monotonic() + 30  # the move takes ~1 s; a loaded shared machine more
        while time.monotonic() < deadline:
            sample = c.call("get")["sample"]
            if sample["pos"] == pytest.approx([20.0, -10.5]):
                break
            time.sleep(0.02)
        assert sample["q"] == pytest.approx([20.0, -10.5])
        assert sample["pos"] == pytest.approx([20.0, -10.5])
        assert sample["state"] == "ENABLED"


def test_disable_takes_the_drives_to_switch_on_disabled(stack: Stack) -> None:
    with stack.client() as c:
        c.call("enable")
        assert c.call("disable")["state"] == "DISABLED"
    assert stack.drives.calls[-1] == "disable"


def test_stop_quick_stops_and_further_sets_are_refused(stack: Stack) -> None:
    with stack.client() as c:
        c.call("enable")
        assert c.call("stop")["state"] == "DISABLED"
        assert "quick_stop" in stack.drives.calls
        assert error_code(c.request("set", q=[1.0, 1.0])) == "not_enabled"


def test_fault_is_reported_and_reset_recovers(stack: Stack) -> None:
    with stack.client() as c:
        c.call("enable")
        stack.drives.emcy(0)
        stack.wait_ticks(3)
        status = c.call("status")
        assert status["state"] == "FAULT"
        assert "emcy" in status["fault"]
        assert error_code(c.request("enable")) == "fault"
        assert error_code(c.request("set", q=[0, 0])) == "not_enabled"
        assert c.call("reset")["state"] == "DISABLED"
        assert c.call("enable")["state"] == "ENABLED"


def test_reset_is_refused_while_the_cause_persists(stack: Stack) -> None:
    with stack.client() as c:
        c.call("enable")
        stack.drives.silent = True
        stack.wait_ticks(8)
        assert c.call("status")["state"] == "FAULT"
        response = c.request("reset")
        assert error_code(response) == "fault"
        assert "stale" in response["error"]["message"]
        stack.drives.silent = False
        stack.wait_ticks(2)
        assert c.call("reset")["state"] == "DISABLED"


def test_subscribe_streams_samples_until_unsubscribe(stack: Stack) -> None:
    with stack.client() as c:
        r = c.request("subscribe", rate_hz=100)
        assert r["ok"] is True
        events = [c.read_message() for _ in range(10)]
        assert all(e["event"] == "sample" and e["id"] == r["id"] for e in events)
        ticks = [e["sample"]["tick"] for e in events]
        assert ticks == sorted(ticks) and len(set(ticks)) == 10
        assert c.call("unsubscribe")["unsubscribed"] is True


def test_subscribe_rate_out_of_range_is_refused(stack: Stack) -> None:
    with stack.client() as c:
        assert error_code(c.request("subscribe", rate_hz=0)) == "out_of_range"
        assert error_code(c.request("subscribe", rate_hz=1e6)) == "out_of_range"


def test_compensation_can_be_switched_off_and_asks_for_a_profile_to_switch_on(
        stack: Stack) -> None:
    with stack.client() as c:
        r = c.call("compensation", enabled=False)
        assert r["enabled"] is False and r["active"] == "none"
        assert error_code(c.request("compensation", enabled=True)) == "no_profile"
        assert c.call("compensation")["enabled"] is False
        assert error_code(c.request("compensation", method="magic")) == "bad_param"


def test_profile_unknown_catheter_is_a_clear_error(stack: Stack) -> None:
    with stack.client() as c:
        response = c.request("profile", catheter="nope-42")
        assert error_code(response) == "profile"
        assert "nope-42" in response["error"]["message"]
        assert error_code(c.request("profile", catheter="../etc/passwd")) == "bad_param"


def test_profile_without_id_lists_the_store(stack: Stack) -> None:
    with stack.client() as c:
        r = c.call("profile")
    assert r["profile"] is None and r["available"] == []


def test_calibrate_without_a_device_model_is_unavailable(stack: Stack) -> None:
    with stack.client() as c:
        assert error_code(c.request("calibrate", catheter="cath-1")) == "unavailable"
        assert c.call("cancel")["cancelled"] is False


# --- refused input ---------------------------------------------------------------------------

@pytest.mark.parametrize(("line", "code"), [
    (b"not json", "bad_json"),
    (b'{"cmd": "set", "q": [NaN, 0]}', "bad_json"),
    (b'{"cmd": "set", "q": [Infinity, 0]}', "bad_json"),
    (b'{"cmd": "set", "q": [1e400, 0]}', "bad_param"),
    (b'{"cmd": "set", "q": [1, 2, 3]}', "bad_param"),
    (b'{"cmd": "set", "q": "10,10"}', "bad_param"),
    (b'{"cmd": "set", "q": [true, 0]}', "bad_param"),
    (b'{"cmd": "set", "q": [null, 0]}', "bad_param"),
    (b'{"cmd": "set"}', "bad_param"),
    (b'{"cmd": "set", "q": [0, 0], "speed": 3}', "bad_param"),
    (b'{"cmd": "launch"}', "unknown_command"),
    (b'{"q": [0, 0]}', "bad_request"),
    (b'{"cmd": 7}', "bad_request"),
    (b"[1, 2]", "bad_request"),
    (b'{"id": [1], "cmd": "status"}', "bad_request"),
    (b'{"id": true, "cmd": "status"}', "bad_request"),
    (b"\xff\xfe{}", "bad_json"),
    (b"[" * 1500 + b"]" * 1500, "bad_json"),
    (b'{"cmd": "set", "q": [1' + b"0" * 400 + b', 0]}', "out_of_range"),
    (b'{"cmd": "set", "q": [-1' + b"0" * 4000 + b', 0]}', "out_of_range"),
    (b'{"cmd": "subscribe", "rate_hz": 1' + b"0" * 400 + b"}", "out_of_range"),
], ids=lambda v: repr(v)[:24])
def test_malformed_request_is_refused_with_its_code(stack: Stack, line: bytes,
                                                    code: str) -> None:
    with stack.client() as c:
        c.call("enable")
        assert error_code(raw(c, line)) == code
    assert all_targets_inside_limits(stack.drives)


def test_out_of_range_setpoint_is_refused_and_never_reaches_the_drives(stack: Stack) -> None:
    with stack.client() as c:
        c.call("enable")
        response = c.request("set", q=[95.0, 0.0])
        assert error_code(response) == "out_of_range"
        assert "q[0]" in response["error"]["message"]
        stack.wait_ticks(5)
    assert all_targets_inside_limits(stack.drives)
    assert stack.loop.setpoint.get() == (0.0, 0.0)


def test_oversized_line_is_refused_and_the_connection_still_works(tmp_path: Path) -> None:
    s = start_stack(tmp_path, max_line_bytes=256)
    try:
        with s.client() as c:
            c.send_raw(b'{"cmd": "status", "pad": "' + b"x" * 100_000 + b'"}\n')
            assert error_code(c.read_message()) == "too_long"
            assert c.call("status")["state"] == "DISABLED"
    finally:
        s.stop.set()
        s.server.stop()


def test_a_newcomer_beyond_the_maximum_evicts_the_least_active_client(tmp_path: Path) -> None:
    s = start_stack(tmp_path, max_clients=2)
    try:
        a, b = s.client(), s.client()
        a.call("status")
        time.sleep(0.01)
        b.call("status")
        with s.client() as c:
            assert c.call("status")["ok"]
            assert error_code(a.read_message()) == "evicted"
            assert b.call("status")["ok"]
        a.close()
        b.close()
    finally:
        s.stop.set()
        s.server.stop()


# --- clients that misbehave do not disturb the loop ------------------------------------------

def test_a_client_that_disconnects_mid_request_does_not_disturb_the_loop(stack: Stack) -> None:
    for _ in range(20):
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.connect(str(stack.path))
        sock.sendall(b'{"cmd": "stat')
        sock.close()
    ticks = stack.loop.stats.ticks
    stack.wait_ticks(10)
    assert stack.loop.stats.ticks >= ticks + 10
    with stack.client() as c:
        assert c.call("status")["ok"]


def test_a_stalled_subscriber_and_a_flooding_client_leave_others_served(stack: Stack) -> None:
    stalled = stack.client()
    stalled.send_raw(b'{"cmd": "subscribe", "rate_hz": 250}\n')  # and never read
    flooder = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    flooder.connect(str(stack.path))
    flooder.setblocking(False)
    request = b'{"cmd": "status"}\n' * 1000
    sent = 0
    deadline = time.monotonic() + 1.0
    while time.monotonic() < deadline:
        try:
            sent += flooder.send(request)
        except BlockingIOError:
            time.sleep(0.001)
    ticks = stack.loop.stats.ticks
    with stack.client() as c:
        c.call("enable")
        c.call("set", q=[5.0, 5.0])
        stack.wait_ticks(20)
        assert c.call("get")["sample"]["q"] == [5.0, 5.0]
    assert stack.loop.stats.ticks >= ticks + 20
    assert stack.loop.state is LoopState.ENABLED
    assert sent > 0
    flooder.close()
    stalled.close()


# --- socat as a client -----------------------------------------------------------------------

def test_socat_client_gets_one_response_per_request(stack: Stack) -> None:
    socat = shutil.which("socat")
    if socat is None:
        pytest.skip("socat is not installed")
    lines = b'{"id":1,"cmd":"status"}\n{"id":2,"cmd":"nope"}\n'
    out = subprocess.run([socat, "-t", "2", "-", f"UNIX-CONNECT:{stack.path}"], input=lines,
                         capture_output=True, timeout=20, check=True).stdout
    responses = [json.loads(line) for line in out.splitlines()]
    assert [r["id"] for r in responses] == [1, 2]
    assert responses[0]["ok"] is True
    assert responses[1]["error"]["code"] == "unknown_command"


def test_client_error_carries_the_code(stack: Stack) -> None:
    with stack.client() as c, pytest.raises(ApiClientError) as exc:
        c.call("set", q=[0, 0])
    assert exc.value.code == "not_enabled"


def test_profile_loads_a_catheter_and_compensation_follows_it(tmp_path: Path) -> None:
    example = Path(__file__).resolve().parent.parent / "profiles" / "example-sim.yaml"
    if not example.exists():
        pytest.skip("profiles/example-sim.yaml is not there")
    store = tmp_path / "store"
    store.mkdir()
    shutil.copy(example, store / "example-sim.yaml")
    s = start_stack(tmp_path, profiles_dir=store)
    try:
        with s.client() as c:
            r = c.call("profile", catheter="example-sim")
            assert r["profile"] == "example-sim" and r["active"] == "ours"
            assert c.call("profile")["available"] == ["example-sim"]
            assert c.call("compensation", method="paper")["active"] == "paper"
            assert c.call("compensation", enabled=False)["active"] == "none"
            status = c.call("status")
            assert status["profile"] == "example-sim"
            assert status["compensation"] == {"enabled": False, "method": "paper",
                                              "active": "none"}
    finally:
        s.stop.set()
        s.server.stop()


def test_a_second_daemon_does_not_steal_a_live_socket(stack: Stack) -> None:
    async def handler(*_: object) -> dict[str, object]:
        return {}

    with pytest.raises(ApiServerError, match="another daemon"):
        ApiServer(stack.path, handler).start()
    with stack.client() as c:
        assert c.call("status")["ok"]


def test_a_stale_socket_file_is_replaced(tmp_path: Path) -> None:
    path = tmp_path / "old.sock"
    old = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    old.bind(str(path))
    old.close()  # a daemon that died left its socket file behind

    async def handler(request: Request, conn: object) -> dict[str, object]:
        return ok(request.id, pong=True)

    server = ApiServer(path, handler)
    server.start()
    try:
        with ApiClient(path) as c:
            assert c.call("status")["pong"] is True
    finally:
        server.stop()


def test_a_huge_integer_gets_an_answer_and_the_connection_stays_usable(stack: Stack) -> None:
    with stack.client() as c:
        c.call("enable")
        response = raw(c, b'{"id": 9, "cmd": "set", "q": [1' + b"0" * 1000 + b", 0]}")
        assert response["id"] == 9 and error_code(response) == "out_of_range"
        assert c.call("status")["ok"]
    assert all_targets_inside_limits(stack.drives)


def test_reset_with_a_silent_drive_answers_fault_naming_it(tmp_path: Path) -> None:
    import dataclasses

    from tsmd.config import default_sim_config
    from tsmd.daemon import Daemon

    base = default_sim_config()
    config = dataclasses.replace(base, profiles=dataclasses.replace(base.profiles, active=None))
    daemon = Daemon(config, sim=True, socket_path=str(tmp_path / "s.sock"))
    daemon.start()
    try:
        with ApiClient(tmp_path / "s.sock") as c:
            c.call("enable")
            daemon.rig.inject_fault("silent", drive=1)
            deadline = time.monotonic() + 5
            while c.call("status")["state"] != "FAULT" and time.monotonic() < deadline:
                time.sleep(0.05)
            time.sleep(0.6)  # past the drive's heartbeat timeout
            response = c.request("reset")
            assert error_code(response) == "fault"
            assert "drive 1 (node 2) silent" in response["error"]["message"]
    finally:
        daemon.stop()
