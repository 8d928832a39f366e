"""The lockstep bus's frames end (the simulated rig's side): frames as tuples, same traffic."""

from __future__ import annotations

import can
import pytest

from simrig.lockstep_bus import ERROR, EXTENDED, REMOTE, LockstepBus


@pytest.fixture()
def ends():
    master = LockstepBus("test-frames")
    rig = LockstepBus("test-frames", frames=True)
    yield master, rig
    master.shutdown()
    rig.shutdown()


def test_a_frames_end_takes_every_frame_once_in_order(ends) -> None:
    master, rig = ends
    for cob in (0x201, 0x202, 0x080):
        master.send(can.Message(arbitration_id=cob, data=bytes((cob & 0xFF,)),
                                is_extended_id=False))
    assert rig.take_frames() == [(0x201, b"\x01", 0), (0x202, b"\x02", 0), (0x080, b"\x80", 0)]
    assert rig.take_frames() == []


def test_a_frame_taken_later_keeps_the_data_it_was_sent_with(ends) -> None:
    master, rig = ends
    msg = can.Message(arbitration_id=0x201, data=bytearray(b"\x01\x02"), is_extended_id=False)
    master.send(msg)
    msg.data[0] = 0xFF  # the master reuses its RPDO frame
    assert rig.take_frames()[0][1] == b"\x01\x02"


def test_a_frames_end_flags_remote_extended_and_error_frames(ends) -> None:
    master, rig = ends
    master.send(can.Message(arbitration_id=0x12345, data=b"", is_extended_id=True))
    master.send(can.Message(arbitration_id=0x701, is_remote_frame=True, is_extended_id=False))
    master.send(can.Message(arbitration_id=0x4, is_error_frame=True, data=bytes(8),
                            is_extended_id=False))
    flags = [f[2] for f in rig.take_frames()]
    assert flags == [EXTENDED, REMOTE, ERROR]


def test_recv_on_a_frames_end_gives_the_message_with_its_flags(ends) -> None:
    master, rig = ends
    master.send(can.Message(arbitration_id=0x701, is_remote_frame=True, is_extended_id=False))
    master.send(can.Message(arbitration_id=0x181, data=b"\x07", is_extended_id=False))
    first, second = rig.recv(0), rig.recv(0)
    assert first is not None and first.is_remote_frame and first.arbitration_id == 0x701
    assert second is not None and bytes(second.data) == b"\x07" and not second.is_remote_frame
    assert rig.recv(0) is None


def test_a_frames_end_going_bus_off_drops_what_is_pending_and_says_so(ends) -> None:
    master, rig = ends
    master.send(can.Message(arbitration_id=0x201, data=b"\x01", is_extended_id=False))
    rig.set_bus_off(True)
    frames = rig.take_frames()
    assert len(frames) == 1 and frames[0][2] == ERROR


def test_take_frames_on_a_message_end_is_refused(ends) -> None:
    master, _ = ends
    with pytest.raises(RuntimeError, match="frames=True"):
        master.take_frames()
