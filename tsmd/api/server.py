"""The Unix-socket server: asyncio in its own thread, so no client can delay a tick.

Per client: lines are cut at ``max_line_bytes`` (longer ones are answered with ``too_long``
and skipped to the next newline), requests are rate-limited by a token bucket (a flooding
client is slowed down by back-pressure, not answered faster), and a client that stops reading
is dropped once its send buffer stays full. Streams (``subscribe``, calibration progress)
drop samples rather than queue them without bound.

Against many clients: connections are accepted at a bounded rate (a connect/close storm waits
in the kernel's backlog instead of taking the GIL from the loop), idle and half-line
connections time out, and when every slot is taken the least active client makes room, so a
local operator can always get in. The server thread never keeps the loop's real-time
priority or core (:meth:`ApiServer._leave_the_loop_alone`).
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import socket
import stat
import threading
import time
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any

from tsmd.api.connection import Connection, TokenBucket, least_active
from tsmd.api.protocol import (
    ApiError,
    Request,
    decode_line,
    error,
    parse_request,
    request_id,
)
from tsmd.errors import TsmdError
from tsmd.rt import set_fifo, set_normal_scheduling

__all__ = ["ApiServer", "ApiServerError", "Connection", "Handler"]

READ_CHUNK_BYTES = 64 * 1024
LISTEN_BACKLOG = 64


class ApiServerError(TsmdError):
    """The socket could not be created (path, permissions); the message says which."""


Handler = Callable[[Request, Connection], Awaitable[dict[str, Any]]]


def _someone_listens(path: Path) -> bool:
    probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    probe.settimeout(1.0)
    try:
        probe.connect(str(path))
    except OSError:
        return False
    finally:
        probe.close()
    return True


class ApiServer:
    """Serves :data:`Handler` on a Unix stream socket from a background thread."""

    def __init__(self, socket_path: str | os.PathLike[str], handler: Handler, *,
                 mode: int = 0o660, max_line_bytes: int = 4096, max_clients: int = 16,
                 requests_per_s: float = 2000.0, accepts_per_s: float = 200.0,
                 idle_timeout_s: float = 30.0, partial_line_timeout_s: float = 5.0,
                 loop_cpu: int | None = None, max_fifo_priority: int = 1,
                 on_event: Callable[..., None] | None = None) -> None:
        for name, value in (("max_clients", max_clients), ("requests_per_s", requests_per_s),
                            ("accepts_per_s", accepts_per_s),
                            ("idle_timeout_s", idle_timeout_s),
                            ("partial_line_timeout_s", partial_line_timeout_s)):
            if not value > 0:
                raise ApiServerError(f"api {name} must be > 0, got {value!r}")
        self.socket_path = Path(socket_path)
        self.handler = handler
        self.mode = mode
        self.max_line_bytes = max_line_bytes
        self.max_clients = max_clients
        self.requests_per_s = requests_per_s
        self.accepts_per_s = accepts_per_s
        self.idle_timeout_s = idle_timeout_s
        self.partial_line_timeout_s = partial_line_timeout_s
        self.loop_cpu = loop_cpu
        """The CPU the control loop is pinned to: the server thread runs on the others."""
        self.max_fifo_priority = max_fifo_priority
        """Highest SCHED_FIFO priority the server thread keeps (0: ordinary scheduling)."""
        self._on_event = on_event
        self.loop: asyncio.AbstractEventLoop | None = None
        self._thread: threading.Thread | None = None
        self._listener: socket.socket | None = None
        self._accept_task: asyncio.Task[None] | None = None
        self._client_tasks: set[asyncio.Task[None]] = set()
        self._connections: set[Connection] = set()
        self.accepted = 0
        self.evicted = 0
        self.timed_out = 0
        self.thread_warnings: list[str] = []
        self._started = threading.Event()
        self._start_error: BaseException | None = None
        self._inode: int | None = None
        self.requests = 0
        self.refused = 0
        self.background_commands: frozenset[str] = frozenset({"calibrate"})
        """Commands answered from their own task, so the client can still send ``cancel``."""

    @property
    def client_count(self) -> int:
        return len(self._connections)

    def start(self) -> None:
        """Bind the socket (mode applied before anyone can connect) and serve in a thread."""
        self._thread = threading.Thread(target=self._run, name="tsmd-api", daemon=True)
        self._thread.start()
        self._started.wait(10.0)
        if self._start_error is not None:
            raise self._start_error

    def _run(self) -> None:
        self.thread_warnings = self._leave_the_loop_alone()
        for warning in self.thread_warnings:
            self._event("warning", "api thread set-up", reason=warning)
        loop = asyncio.new_event_loop()
        self.loop = loop
        try:
            loop.run_until_complete(self._bind())
        except BaseException as exc:  # reported to start()'s caller
            self._start_error = exc
            self._started.set()
            loop.close()
            return
        self._started.set()
        try:
            loop.run_forever()
        finally:
            loop.run_until_complete(self._shutdown())
            loop.close()

    async def _bind(self) -> None:
        path = self.socket_path
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ApiServerError(f"cannot create socket directory {path.parent}: "
                                 f"{exc.strerror or exc}") from None
        if path.exists() or path.is_symlink():
            if not stat.S_ISSOCK(path.lstat().st_mode):
                raise ApiServerError(f"{path} exists and is not a socket; refusing to replace it")
            if _someone_listens(path):
                raise ApiServerError(f"another daemon is listening on {path}; stop it first "
                                     "or choose another socket (--socket)")
            path.unlink()  # left over by a daemon that died
        listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        old_umask = os.umask(0o777 & ~self.mode)
        try:
            listener.bind(str(path))
            listener.listen(LISTEN_BACKLOG)
        except OSError as exc:
            listener.close()
            raise ApiServerError(f"cannot listen on {path}: {exc.strerror or exc}") from None
        finally:
            os.umask(old_umask)
        listener.setblocking(False)
        self._listener = listener
        os.chmod(path, self.mode)
        self._inode = path.stat().st_ino
        self._accept_task = asyncio.ensure_future(self._accept_loop(listener))

    def _leave_the_loop_alone(self) -> list[str]:
        """Off the loop's core, and no higher than the helper priority (runs in our thread).

        A thread inherits its creator's policy and affinity: started from a thread pinned or
        raised for the loop, the server would compete with the loop for its core.
        """
        problems: list[str] = []
        if self.loop_cpu is not None:
            try:
                others = os.sched_getaffinity(0) - {self.loop_cpu}
                if others:
                    os.sched_setaffinity(0, others)
            except (OSError, AttributeError) as exc:
                problems.append(f"cannot move off CPU {self.loop_cpu}: {exc}")
        try:
            policy = os.sched_getscheduler(0)
            priority = os.sched_getparam(0).sched_priority
        except (OSError, AttributeError):
            return problems
        if policy in (os.SCHED_FIFO, os.SCHED_RR) and priority > self.max_fifo_priority:
            problem = (set_fifo(self.max_fifo_priority) if self.max_fifo_priority > 0
                       else set_normal_scheduling())
            if problem is not None:
                problems.append(problem)
        return problems

    async def _accept_loop(self, listener: socket.socket) -> None:
        """Accept at most ``accepts_per_s`` (burst 1/10 s): a storm waits in the backlog."""
        loop = asyncio.get_running_loop()
        bucket = TokenBucket(self.accepts_per_s, burst=max(1.0, self.accepts_per_s / 10.0))
        while True:
            delay = bucket.wait_s()
            if delay > 0:
                await asyncio.sleep(delay)
            try:
                client, _ = await loop.sock_accept(listener)
            except OSError as exc:  # e.g. out of file descriptors: back off, never spin
                self._event("warning", "api accept failed", reason=exc.strerror or str(exc))
                await asyncio.sleep(0.1)
                continue
            self.accepted += 1
            try:
                reader, writer = await asyncio.open_unix_connection(sock=client)
            except OSError:
                client.close()
                continue
            task = asyncio.ensure_future(self._client(reader, writer))
            self._client_tasks.add(task)
            task.add_done_callback(self._client_tasks.discard)

    async def _shutdown(self) -> None:
        if self._accept_task is not None:
            self._accept_task.cancel()
            await asyncio.gather(self._accept_task, return_exceptions=True)
        if self._listener is not None:
            self._listener.close()
        for conn in list(self._connections):
            conn.close()  # cancels its streams; its reader then sees the end and returns
        await asyncio.sleep(0)
        tasks = [t for t in asyncio.all_tasks() if t is not asyncio.current_task()]
        if tasks:
            _, pending = await asyncio.wait(tasks, timeout=1.0)
            for task in pending:
                task.cancel()
            await asyncio.gather(*pending, return_exceptions=True)
        with contextlib.suppress(OSError):
            if self.socket_path.stat().st_ino == self._inode:  # never another daemon's socket
                self.socket_path.unlink()

    def stop(self) -> None:
        loop = self.loop
        if loop is None or self._thread is None:
            return
        with contextlib.suppress(RuntimeError):
            loop.call_soon_threadsafe(loop.stop)
        self._thread.join(5.0)

    async def _client(self, reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        conn = Connection(writer)
        if len(self._connections) >= self.max_clients:
            victim = least_active(self._connections)
            if victim is None:
                self.refused += 1
                await conn.reply(error(None, "too_many_clients",
                                       f"at most {self.max_clients} clients at a time"))
                conn.close()
                return
            self.evicted += 1
            self._connections.discard(victim)
            await victim.reply(error(None, "evicted", f"all {self.max_clients} client slots "
                                     "are taken; this connection was the least active"))
            victim.close()
        self._connections.add(conn)
        bucket = TokenBucket(self.requests_per_s, burst=min(self.requests_per_s, 200.0))
        buf = bytearray()
        line_started_s = 0.0
        discarding = False
        try:
            while not conn.closed:
                now = time.monotonic()
                if buf or discarding:
                    timeout = self.partial_line_timeout_s - (now - line_started_s)
                else:
                    timeout = self.idle_timeout_s - (now - conn.last_request_s)
                try:
                    data = await asyncio.wait_for(reader.read(READ_CHUNK_BYTES),
                                                  max(timeout, 0.0))
                except TimeoutError:
                    if not (buf or discarding) and conn.streaming:
                        conn.last_request_s = time.monotonic()  # streams keep a client alive
                        continue
                    await self._time_out(conn, partial=bool(buf or discarding))
                    break
                if not data:
                    break
                if not (buf or discarding):
                    line_started_s = time.monotonic()
                buf += data
                while not conn.closed:
                    nl = buf.find(b"\n")
                    if nl < 0:
                        if len(buf) > self.max_line_bytes:
                            if not discarding:
                                await conn.reply(self._too_long())
                            discarding = True
                            buf.clear()
                        break
                    line = bytes(buf[:nl])
                    del buf[:nl + 1]
                    line_started_s = time.monotonic()  # the next line starts now
                    if discarding:
                        discarding = False
                        continue
                    if len(line) > self.max_line_bytes:
                        await conn.reply(self._too_long())
                        continue
                    if not line.strip():
                        continue
                    conn.last_request_s = time.monotonic()
                    delay = bucket.wait_s()
                    if delay > 0:
                        await asyncio.sleep(delay)
                    response = await self._dispatch(line, conn)
                    if response is not None:
                        await conn.reply(response)
            # The client closed its sending side: answer what runs (streams, calibration)
            # until it closes the connection or the tasks end.
            pending = [t for t in conn.tasks.values() if not t.done()]
            if pending and not conn.closed:
                await asyncio.gather(*pending, return_exceptions=True)
        except (ConnectionError, asyncio.IncompleteReadError):
            pass
        finally:
            self._connections.discard(conn)
            conn.close()

    async def _time_out(self, conn: Connection, partial: bool) -> None:
        self.timed_out += 1
        if partial:
            message = (f"no end of line within {self.partial_line_timeout_s:g} s of its start; "
                       "closing")
        else:
            message = f"no request for {self.idle_timeout_s:g} s; closing"
        await conn.reply(error(None, "line_timeout" if partial else "idle_timeout", message))
        conn.close()

    def _event(self, level: str, message: str, **fields: Any) -> None:
        if self._on_event is not None:
            self._on_event(level, message, **fields)

    def _too_long(self) -> dict[str, Any]:
        return error(None, "too_long", f"request line longer than {self.max_line_bytes} bytes")

    async def _dispatch(self, line: bytes, conn: Connection) -> dict[str, Any] | None:
        """The response, or None when a long command answers later from its own task."""
        self.requests += 1
        obj: Any = None
        try:
            obj = decode_line(line)
            request = parse_request(obj)
        except ApiError as exc:
            return error(request_id(obj), exc.code, exc.message)
        except Exception as exc:  # every request gets an answer, whatever the parser missed
            self._event("error", "api request not parsed", error=type(exc).__name__)
            return error(request_id(obj), "bad_request",
                         f"request not understood ({type(exc).__name__})")
        if request.cmd in self.background_commands:
            conn.start_task(f"{request.cmd}:{request.id}", self._answer_later(request, conn))
            return None
        return await self._handle(request, conn)

    async def _answer_later(self, request: Request, conn: Connection) -> None:
        await conn.reply(await self._handle(request, conn))

    async def _handle(self, request: Request, conn: Connection) -> dict[str, Any]:
        try:
            return await self.handler(request, conn)
        except ApiError as exc:
            return error(request.id, exc.code, exc.message)
        except Exception as exc:  # a handler bug must not end the server
            self._event("error", "api handler failed", error=repr(exc))
            return error(request.id, "internal", f"internal error: {exc}")

