"""The API fuzzed: whatever a client sends, every target sent to the drives stays in limits.

Random bytes, huge lines, deeply nested JSON, NaN/inf, wrong types and valid commands mixed;
each line gets exactly one well-formed response and the loop keeps ticking.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from support.api import PERIOD_S, all_targets_inside_limits, start_stack

json_scalars = st.one_of(
    st.none(), st.booleans(), st.integers(min_value=-(10**30), max_value=10**30),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=20))
json_values = st.recursive(
    json_scalars,
    lambda children: st.one_of(st.lists(children, max_size=4),
                               st.dictionaries(st.text(max_size=8), children, max_size=4)),
    max_leaves=20)
commands = st.sampled_from(["status", "enable", "disable", "stop", "reset", "set", "get",
                            "subscribe", "unsubscribe", "compensation", "profile", "cancel",
                            "bogus", ""])
angles = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                   st.floats(min_value=-200, max_value=200), st.integers(-1000, 1000),
                   st.booleans(), st.none(), st.text(max_size=3))


def _json_line(obj: object) -> bytes:
    return json.dumps(obj).encode()  # NaN/Infinity come out as bare tokens, on purpose


requests = st.one_of(
    st.builds(lambda q: _json_line({"cmd": "set", "q": q}),
              st.lists(angles, min_size=0, max_size=3)),
    st.builds(lambda c, q: _json_line({"id": 1, "cmd": c, "q": q}), commands, json_values),
    st.builds(lambda d: _json_line(d), st.dictionaries(st.text(max_size=6), json_values,
                                                       max_size=5)),
    st.builds(lambda v: _json_line({"cmd": "subscribe", "rate_hz": v}), angles),
    st.builds(lambda v: _json_line(v), json_values),
    st.binary(max_size=300),
    st.integers(1, 2000).map(lambda n: b"[" * n + b"]" * n),
    st.integers(1, 2000).map(lambda n: b'{"a":' * n + b"1" + b"}" * n),
    st.integers(5000, 50000).map(lambda n: b'{"cmd":"set","q":[1,' + b"1" * n + b"]}"),
    st.just(b'{"cmd": "enable"}'),
    st.floats(-90, 90).map(lambda v: _json_line({"cmd": "set", "q": [v, -v]})),
)


def test_fuzzed_requests_never_move_a_knob_outside_its_limits(tmp_path: Path) -> None:
    stack = start_stack(tmp_path)
    client = stack.client()
    answered = 0

    @settings(max_examples=400, deadline=None, derandomize=True,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(st.lists(requests, min_size=1, max_size=5))
    def exchange(lines: list[bytes]) -> None:
        nonlocal answered
        for line in lines:
            line = line.replace(b"\n", b" ").replace(b"\r", b" ")
            if not line.strip():
                continue
            client.send_raw(line + b"\n")
            response = client.read_message()
            while "event" in response:  # samples of a subscription, not an answer
                response = client.read_message()
            assert isinstance(response.get("ok"), bool)
            if not response["ok"]:
                assert response["error"]["code"] and response["error"]["message"]
            answered += 1

    try:
        exchange()
        ticks = stack.loop.stats.ticks
        stack.wait_ticks(5)
        assert stack.loop.stats.ticks >= ticks + 5
        assert answered > 100
        assert all_targets_inside_limits(stack.drives)
        assert len(stack.drives.targets) > 0
        steps = np.abs(np.diff(stack.drives.targets_array(), axis=0))
        assert steps.max() <= 120.0 * PERIOD_S + 1e-9  # the velocity limit, every tick
    finally:
        client.close()
        stack.stop.set()
        stack.server.stop()
