"""The socket server's own limits: timeouts, eviction, accept rate, and its thread's scheduling.

These run the server with a trivial handler (no loop): what is tested is the server itself.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tsmd.api.protocol import Request, ok
from tsmd.api.server import ApiServer, Connection
from tsmd.rt import set_fifo, set_normal_scheduling


async def echo(request: Request, conn: Connection) -> dict[str, Any]:
    if request.cmd == "subscribe":
        async def stream() -> None:
            while True:
                conn.send_event({"id": request.id, "event": "sample"})
                await asyncio.sleep(0.05)

        conn.start_task("subscribe", stream())
    return ok(request.id, cmd=request.cmd)


def start(tmp_path: Path, **kwargs: Any) -> ApiServer:
    server = ApiServer(tmp_path / "s.sock", echo, **kwargs)
    server.start()
    return server


@pytest.fixture
def short_timeouts(tmp_path: Path) -> Iterator[ApiServer]:
    server = start(tmp_path, idle_timeout_s=0.4, partial_line_timeout_s=0.3)
    yield server
    server.stop()


def connect(server: ApiServer) -> socket.socket:
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.settimeout(5.0)
    sock.connect(str(server.socket_path))
    return sock


def read_line(sock: socket.socket) -> dict[str, Any]:
    data = b""
    while not data.endswith(b"\n"):
        chunk = sock.recv(4096)
        if not chunk:
            raise ConnectionError(f"closed after {data!r}")
        data += chunk
    message: dict[str, Any] = json.loads(data.split(b"\n")[0])
    return message


def closed_by_server(sock: socket.socket) -> bool:
    try:
        rest = sock.recv(4096)
        while rest:
            rest = sock.recv(4096)
    except ConnectionError:
        pass
    return True


def test_an_idle_connection_is_told_and_closed_after_the_idle_timeout(
        short_timeouts: ApiServer) -> None:
    sock = connect(short_timeouts)
    t0 = time.monotonic()
    message = read_line(sock)
    waited = time.monotonic() - t0
    assert message["error"]["code"] == "idle_timeout"
    assert "no request for 0.4 s" in message["error"]["message"]
    assert 0.3 <= waited < 2.0
    assert closed_by_server(sock)


def test_a_half_line_is_closed_after_the_partial_line_timeout(
        short_timeouts: ApiServer) -> None:
    sock = connect(short_timeouts)
    sock.sendall(b'{"cmd": "sta')
    t0 = time.monotonic()
    message = read_line(sock)
    assert message["error"]["code"] == "line_timeout"
    assert "no end of line within 0.3 s" in message["error"]["message"]
    assert time.monotonic() - t0 < 0.4  # the partial-line limit, not the idle one


def test_a_trickling_half_line_does_not_reset_the_partial_line_timeout(
        short_timeouts: ApiServer) -> None:
    sock = connect(short_timeouts)
    t0 = time.monotonic()
    with pytest.raises(OSError):
        for _ in range(20):
            sock.sendall(b" ")
            time.sleep(0.05)
    assert time.monotonic() - t0 < 1.0


def test_requests_keep_a_connection_alive(short_timeouts: ApiServer) -> None:
    sock = connect(short_timeouts)
    for _ in range(6):
        time.sleep(0.15)
        sock.sendall(b'{"cmd": "status"}\n')
        assert read_line(sock)["ok"]


def test_a_subscriber_that_only_listens_is_not_idle(short_timeouts: ApiServer) -> None:
    sock = connect(short_timeouts)
    sock.sendall(b'{"id": 1, "cmd": "subscribe"}\n')
    deadline = time.monotonic() + 1.0
    while time.monotonic() < deadline:
        assert "error" not in read_line(sock)


def test_when_full_an_idle_client_makes_room_before_a_streaming_one(tmp_path: Path) -> None:
    server = start(tmp_path, max_clients=2)
    try:
        streaming = connect(server)
        streaming.sendall(b'{"id": 1, "cmd": "subscribe"}\n')
        read_line(streaming)
        idle = connect(server)
        time.sleep(0.1)
        newcomer = connect(server)
        newcomer.sendall(b'{"cmd": "status"}\n')
        assert read_line(newcomer)["ok"]
        assert read_line(idle)["error"]["code"] == "evicted"
        assert server.evicted == 1
        assert "error" not in read_line(streaming)
    finally:
        server.stop()


def test_sixteen_idle_connections_do_not_lock_out_an_operator(tmp_path: Path) -> None:
    server = start(tmp_path, max_clients=16)
    try:
        squatters = [connect(server) for _ in range(16)]
        for sock in squatters:
            sock.sendall(b'{"cmd": "st')  # half lines, never finished
        operator = connect(server)
        operator.sendall(b'{"cmd": "status"}\n')
        assert read_line(operator)["ok"]
    finally:
        server.stop()


def test_accepts_are_rate_limited_during_a_connect_storm(tmp_path: Path) -> None:
    server = start(tmp_path, accepts_per_s=100.0)
    stop = threading.Event()

    def storm() -> None:
        while not stop.is_set():
            sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            sock.setblocking(False)
            with contextlib.suppress(OSError):  # backlog full: the storm waits in the kernel
                sock.connect(str(server.socket_path))
            sock.close()

    try:
        thread = threading.Thread(target=storm, daemon=True)
        t0 = time.monotonic()
        thread.start()
        time.sleep(1.0)
        stop.set()
        thread.join()
        elapsed = time.monotonic() - t0
        assert server.accepted <= 100.0 * elapsed + 10 + 1  # rate plus the burst
        assert server.accepted >= 20
    finally:
        server.stop()


def test_the_server_thread_leaves_the_loops_cpu(tmp_path: Path) -> None:
    cpus = sorted(os.sched_getaffinity(0))
    if len(cpus) < 2:
        pytest.skip("needs two CPUs")
    server = start(tmp_path, loop_cpu=cpus[0])
    try:
        assert server._thread is not None and server._thread.native_id is not None
        assert cpus[0] not in os.sched_getaffinity(server._thread.native_id)
    finally:
        server.stop()


def test_the_server_thread_does_not_keep_the_loops_fifo_priority(tmp_path: Path) -> None:
    result: dict[str, Any] = {}

    def start_from_a_realtime_thread() -> None:
        refused = set_fifo(50)
        if refused is not None:
            result["skip"] = refused
            return
        server = start(tmp_path, max_fifo_priority=1)
        assert server._thread is not None and server._thread.native_id is not None
        result["priority"] = os.sched_getparam(server._thread.native_id).sched_priority
        server.stop()
        set_normal_scheduling()

    thread = threading.Thread(target=start_from_a_realtime_thread)
    thread.start()
    thread.join()
    if "skip" in result:
        pytest.skip(result["skip"])
    assert result["priority"] == 1
