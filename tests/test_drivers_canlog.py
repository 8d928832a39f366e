"""A tapped bus hands every frame sent and received to python-can listeners, in the caller's
thread, and stops them when it shuts down."""

from __future__ import annotations

import os

import can

from drivers.canlog import TappedBus


def test_sent_and_received_frames_reach_the_listener_and_shutdown_stops_it() -> None:
    channel = f"tsmd-tap-{os.getpid()}"
    peer = can.Bus(interface="virtual", channel=channel)
    buffer = can.BufferedReader()
    bus = TappedBus(can.Bus(interface="virtual", channel=channel), [buffer])
    try:
        bus.send(can.Message(arbitration_id=0x080, data=b"", is_extended_id=False))
        peer.send(can.Message(arbitration_id=0x181, data=b"\x01", is_extended_id=False))
        assert bus.recv(1.0) is not None
        assert bus.recv(0.0) is None  # nothing else on the bus, nothing else logged
    finally:
        bus.shutdown()
        peer.shutdown()
    seen = [buffer.get_message(0.0) for _ in range(3)]
    assert [m.arbitration_id if m is not None else None for m in seen] == [0x080, 0x181, None]
    assert buffer.is_stopped
