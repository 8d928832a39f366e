"""The socket protocol: one JSON object per line in, one JSON object per line out.

Parsing is strict and total: any byte string either becomes a :class:`Request` whose
parameters have the documented types and ranges, or an :class:`ApiError` with a code and a
message. Nothing that fails here can reach the loop. The protocol is specified in docs/api.md.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from typing import Any

from tsmd.compensation import METHODS

MAX_ID_CHARS = 128


class ApiError(Exception):
    """A refused request: ``code`` is stable for programs, ``message`` is for people."""

    def __init__(self, code: str, message: str) -> None:
        super().__init__(message)
        self.code = code
        self.message = message


@dataclass(frozen=True)
class Request:
    cmd: str
    id: str | int | None = None
    params: dict[str, Any] = field(default_factory=dict)


# command -> {parameter: required?}
COMMANDS: dict[str, dict[str, bool]] = {
    "status": {},
    "enable": {},
    "disable": {},
    "stop": {},
    "reset": {},
    "set": {"q": True},
    "get": {},
    "subscribe": {"rate_hz": False},
    "unsubscribe": {},
    "compensation": {"enabled": False, "method": False},
    "profile": {"catheter": False},
    "calibrate": {"catheter": True},
    "cancel": {},
    "home": {"drives": False},
    "online": {"enabled": False},
    "online_save": {},
}



def _reject_constant(name: str) -> Any:
    raise ApiError("bad_json", f"{name} is not allowed (numbers must be finite)")


def decode_line(line: bytes) -> Any:
    """Bytes of one line -> a JSON value; NaN, Infinity, bad UTF-8 and deep nesting refused."""
    try:
        text = line.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ApiError("bad_json", f"not UTF-8 text at byte {exc.start}") from None
    try:
        return json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise ApiError("bad_json", f"not valid JSON: {exc.msg} at column {exc.colno}") from None
    except RecursionError:
        raise ApiError("bad_json", "JSON nested too deeply") from None
    except ValueError as exc:  # e.g. integers with too many digits
        raise ApiError("bad_json", f"not valid JSON: {exc}") from None


def request_id(obj: Any) -> str | int | None:
    """The id to echo, when the object carries a valid one (even if the rest is wrong)."""
    if not isinstance(obj, dict):
        return None
    value = obj.get("id")
    if isinstance(value, bool):
        return None
    if isinstance(value, int) and abs(value) < 2**63:
        return value
    if isinstance(value, str) and len(value) <= MAX_ID_CHARS:
        return value
    return None


def parse_request(obj: Any) -> Request:
    """Validate a decoded JSON value as a request (types only; ranges need the limits)."""
    if not isinstance(obj, dict):
        raise ApiError("bad_request", f"a request must be a JSON object, got {_kind(obj)}")
    if "id" in obj and obj["id"] is not None and request_id(obj) is None:
        raise ApiError("bad_request",
                       f"'id' must be a string (<= {MAX_ID_CHARS} chars) or an integer")
    cmd = obj.get("cmd")
    if not isinstance(cmd, str):
        raise ApiError("bad_request", "missing 'cmd' (a string naming the command)")
    spec = COMMANDS.get(cmd)
    if spec is None:
        raise ApiError("unknown_command",
                       f"unknown command {cmd[:40]!r}; known: {', '.join(COMMANDS)}")
    params = {k: v for k, v in obj.items() if k not in ("id", "cmd")}
    unknown = sorted(set(params) - set(spec))
    if unknown:
        raise ApiError("bad_param", f"{cmd}: unknown parameter(s) {', '.join(unknown)[:80]}")
    for name, required in spec.items():
        if required and name not in params:
            raise ApiError("bad_param", f"{cmd}: missing parameter {name!r}")
    _check_types(cmd, params)
    return Request(cmd, request_id(obj), params)


def _check_types(cmd: str, params: dict[str, Any]) -> None:
    if cmd == "set":
        q = params["q"]
        if not isinstance(q, list) or len(q) != 2:
            raise ApiError("bad_param",
                           "set: 'q' must be a list of two numbers [phi1_deg, phi2_deg]")
        for i, v in enumerate(q):
            if isinstance(v, bool) or not isinstance(v, int | float):
                raise ApiError("bad_param", f"set: q[{i}] must be a number, got {_kind(v)}")
        params["q"] = [_number(cmd, f"q[{i}]", v) for i, v in enumerate(q)]
    elif cmd == "subscribe" and "rate_hz" in params:
        params["rate_hz"] = _number(cmd, "rate_hz", params["rate_hz"])
    elif cmd == "compensation":
        if "enabled" in params and not isinstance(params["enabled"], bool):
            raise ApiError("bad_param", "compensation: 'enabled' must be true or false")
        if "method" in params and params["method"] not in METHODS:
            raise ApiError("bad_param",
                           f"compensation: 'method' must be one of {', '.join(METHODS)}")
    elif cmd == "online" and "enabled" in params and not isinstance(params["enabled"], bool):
        raise ApiError("bad_param", "online: 'enabled' must be true or false")
    elif cmd == "home" and "drives" in params:
        drives = params["drives"]
        if (not isinstance(drives, list) or not drives or len(drives) > 16
                or any(isinstance(i, bool) or not isinstance(i, int) or not 0 <= i < 16
                       for i in drives) or len(set(drives)) != len(drives)):
            raise ApiError("bad_param", "home: 'drives' must be a non-empty list of distinct "
                                        "drive indices (0 = phi1, 1 = phi2)")
    elif cmd in ("profile", "calibrate") and "catheter" in params:
        catheter = params["catheter"]
        if not isinstance(catheter, str) or not is_catheter_id(catheter):
            raise ApiError("bad_param", f"{cmd}: 'catheter' must be an id of 1-64 letters, "
                                        "digits, '-', '_' or '.' (not starting with '.')")


def is_catheter_id(text: str) -> bool:
    return (0 < len(text) <= 64 and not text.startswith(".")
            and all(c.isascii() and (c.isalnum() or c in "-_.") for c in text))


def _number(cmd: str, name: str, value: Any) -> float:
    """A JSON number as a finite float; an integer too large for a float is out of range."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ApiError("bad_param", f"{cmd}: {name} must be a finite number, got {_kind(value)}")
    try:
        number = float(value)
    except OverflowError:  # integers of 309+ digits: float() cannot hold them
        raise ApiError("out_of_range", f"{cmd}: {name} has {len(str(abs(value)))} digits, "
                                       "far outside any valid value") from None
    if not math.isfinite(number):
        raise ApiError("bad_param", f"{cmd}: {name} must be finite")
    return number


def _kind(value: Any) -> str:
    return {dict: "an object", list: "a list", str: "a string", bool: "a boolean",
            type(None): "null"}.get(type(value), "a number")


def ok(req_id: str | int | None, **fields: Any) -> dict[str, Any]:
    return {"id": req_id, "ok": True, **fields}


def error(req_id: str | int | None, code: str, message: str) -> dict[str, Any]:
    return {"id": req_id, "ok": False, "error": {"code": code, "message": message}}


def encode(message: dict[str, Any]) -> bytes:
    """One line of JSON; non-finite floats become null (JSON has no NaN)."""
    return (json.dumps(_finite(message), separators=(",", ":"), allow_nan=False, default=str)
            .encode("utf-8") + b"\n")


def _finite(value: Any) -> Any:
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value
