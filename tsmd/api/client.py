"""A small blocking client for the socket API (the demo, the CLI, tests)."""

from __future__ import annotations

import itertools
import json
import socket
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from tsmd.errors import TsmdError


class ApiClientError(TsmdError):
    """The daemon refused a request (``code`` from its error) or could not be reached."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(f"{code}: {message}")
        self.code = code


class ApiClient:
    """One connection; :meth:`call` sends a request and returns its response's fields."""

    def __init__(self, path: str | Path, timeout_s: float = 30.0) -> None:
        self.path = str(path)
        try:
            self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            self.sock.settimeout(timeout_s)
            self.sock.connect(self.path)
        except OSError as exc:
            raise ApiClientError("unreachable", f"cannot connect to {self.path}: "
                                                f"{exc.strerror or exc}") from None
        self._reader = self.sock.makefile("rb")
        self._ids = itertools.count(1)
        self.events: list[dict[str, Any]] = []

    def send_raw(self, data: bytes) -> None:
        self.sock.sendall(data)

    def read_message(self) -> dict[str, Any]:
        line = self._reader.readline()
        if not line:
            raise ApiClientError("closed", "the daemon closed the connection")
        message: dict[str, Any] = json.loads(line)
        return message

    def messages(self) -> Iterator[dict[str, Any]]:
        while True:
            yield self.read_message()

    def request(self, cmd: str, on_event: Callable[[dict[str, Any]], None] | None = None,
                **params: Any) -> dict[str, Any]:
        """The raw response to one request; events that arrive meanwhile go to ``on_event``."""
        req_id = next(self._ids)
        self.send_raw(json.dumps({"id": req_id, "cmd": cmd, **params}).encode() + b"\n")
        while True:
            message = self.read_message()
            if "event" in message:
                if on_event is not None and message.get("id") == req_id:
                    on_event(message)
                else:
                    self.events.append(message)
                continue
            if message.get("id") == req_id or message.get("id") is None:
                return message

    def call(self, cmd: str, on_event: Callable[[dict[str, Any]], None] | None = None,
             **params: Any) -> dict[str, Any]:
        """Like :meth:`request`, raising :class:`ApiClientError` on ``ok: false``."""
        response = self.request(cmd, on_event, **params)
        if not response.get("ok"):
            err = response.get("error") or {}
            raise ApiClientError(str(err.get("code", "error")), str(err.get("message", "")))
        return response

    def close(self) -> None:
        self._reader.close()
        self.sock.close()

    def __enter__(self) -> ApiClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
