"""Each fault yields its documented event in its documented time (see docs/drivers.md)."""

from __future__ import annotations

import time

import can
import numpy as np
import pytest
from support.drives import open_enabled_rig, tick
from support.plants import SpringPlant

from drivers import canopen_master
from drivers.canopen_master import CanOpenDrives
from drivers.drive import DriveError, DriveState, FaultKind
from drivers.master_homing import MasterHoming
from drivers.master_supervision import MAX_PENDING_BUS_EVENTS
from drivers.units import DriveConfig
from simrig.lockstep_bus import LockstepBus
from simrig.rig import SimRig, open_sim_rig

PERIOD_S = 0.004


@pytest.fixture()
def enabled():
    drives, rig = open_enabled_rig(5, PERIOD_S)
    yield drives, rig
    drives.close()
    rig.close()


def run_until(drives, rig, kind: FaultKind, max_ticks: int, q=(0.0, 0.0)):
    for k in range(1, max_ticks + 1):
        tick(drives, rig, q)
        events = [e for e in drives.poll_events() if e.kind is kind]
        if events:
            return k, events[0]
    raise AssertionError(f"no {kind} event within {max_ticks} ticks")


def test_heartbeat_loss_is_reported_within_the_timeout(enabled):
    drives, rig = enabled
    tick(drives, rig, n=20)  # a heartbeat every 50 ms: last one at most 50 ms old
    rig.inject_fault("heartbeat_stop", drive=1)
    t0 = rig.clock.now_s()
    timeout_s = DriveConfig(node_id=2).heartbeat_timeout_ms * 1e-3
    _ticks, event = run_until(drives, rig, FaultKind.HEARTBEAT_LOST, 200)
    assert event.drive == 1
    assert "node 2" in event.message
    assert event.t_s - t0 <= timeout_s + PERIOD_S + 1e-9
    assert event.t_s - t0 >= timeout_s - 0.05 - 1e-9


def test_heartbeat_loss_alone_does_not_make_feedback_stale(enabled):
    drives, rig = enabled
    rig.inject_fault("heartbeat_stop", drive=0)
    tick(drives, rig, n=100)
    kinds = {e.kind for e in drives.poll_events()}
    assert kinds == {FaultKind.HEARTBEAT_LOST}


def test_silent_node_gives_stale_feedback_after_n_syncs_and_heartbeat_loss(enabled):
    drives, rig = enabled
    n = DriveConfig(node_id=1).stale_after_syncs
    rig.inject_fault("silent", drive=0)
    ticks, event = run_until(drives, rig, FaultKind.STALE_FEEDBACK, 50)
    assert ticks == n
    assert event.drive == 0
    assert drives.feedback()[0].age_syncs == n
    _, lost = run_until(drives, rig, FaultKind.HEARTBEAT_LOST, 100)
    assert lost.drive == 0


def test_stale_feedback_is_reported_once_until_refreshed(enabled):
    drives, rig = enabled
    rig.inject_fault("silent", drive=1)
    tick(drives, rig, n=10)
    stale = [e for e in drives.poll_events() if e.kind is FaultKind.STALE_FEEDBACK]
    assert len(stale) == 1
    rig.clear_fault(1)
    tick(drives, rig, n=2)
    assert drives.feedback()[1].age_syncs == 0


def test_emcy_is_decoded_in_the_same_tick_and_the_drive_faults(enabled):
    drives, rig = enabled
    rig.inject_fault("emcy", drive=0, code=0x2310)
    tick(drives, rig)
    events = drives.poll_events()
    emcy = [e for e in events if e.kind is FaultKind.EMCY]
    assert len(emcy) == 1 and emcy[0].code == 0x2310
    assert "over-current" in emcy[0].message and "error register 0x01" in emcy[0].message
    fault = [e for e in events if e.kind is FaultKind.DRIVE_FAULT]
    assert fault and fault[0].drive == 0 and fault[0].code == 0x2310
    assert drives.feedback()[0].state is DriveState.FAULT
    assert drives.sdo_read(0, 0x603F) == 0x2310


def test_fault_then_reset_then_enable_resumes_streaming(enabled):
    drives, rig = enabled
    rig.inject_fault("emcy", drive=1, code=0x4310)
    tick(drives, rig, n=3)
    with pytest.raises(DriveError, match=r"drive 1 \(node 2\): cannot enable, drive is in FAULT "
                                         r"\(0x603F error code 0x4310 drive over-temperature\)"):
        drives.enable()
    drives.fault_reset()
    assert drives.feedback()[1].state is DriveState.SWITCH_ON_DISABLED
    assert drives.sdo_read(1, 0x603F) == 0
    drives.enable()
    tick(drives, rig, q=(5.0, -5.0), n=100)
    assert np.allclose([f.position_deg for f in drives.feedback()], [5.0, -5.0], atol=0.01)


def test_following_error_faults_the_drive_with_emcy_8611(enabled):
    drives, rig = enabled
    rig.inject_fault("following_error", drive=0)  # the motor jams
    q = np.linspace(0.0, 30.0, 200)
    detected_at = None
    for k, qk in enumerate(q):
        tick(drives, rig, q=(qk, 0.0))
        events = drives.poll_events()
        if any(e.kind is FaultKind.EMCY for e in events):
            detected_at = k
            break
    assert detected_at is not None
    emcy = [e for e in events if e.kind is FaultKind.EMCY]
    assert emcy[0].code == 0x8611 and "following error" in emcy[0].message
    window = DriveConfig(node_id=1).following_error_deg
    timeout_s = DriveConfig(node_id=1).following_error_timeout_ms * 1e-3
    # the target passed the window at q = window, then the timeout ran out
    passed_at = int(np.argmax(q > window))
    assert detected_at - passed_at <= round(timeout_s / PERIOD_S) + 2
    tick(drives, rig, n=2)
    assert drives.feedback()[0].state is DriveState.FAULT


def test_master_silence_makes_the_drive_quick_stop_with_emcy_8130(enabled):
    drives, rig = enabled
    for _ in range(100):  # the master stops sending (no SYNC, no heartbeat); the rig runs on
        rig.exchange()
    drives.pump()
    emcy = [e for e in drives.poll_events() if e.kind is FaultKind.EMCY]
    assert {e.code for e in emcy} == {0x8130}
    assert all("heartbeat" in e.message for e in emcy)
    tick(drives, rig)
    assert [f.state for f in drives.feedback()] == [DriveState.QUICK_STOP_ACTIVE] * 2
    drives.enable()  # option 6: straight back from QUICK STOP ACTIVE
    assert [f.state for f in drives.feedback()] == [DriveState.OPERATION_ENABLED] * 2


def test_quick_stop_holds_and_enable_resumes(enabled):
    drives, rig = enabled
    tick(drives, rig, q=(10.0, 10.0), n=100)
    drives.quick_stop()
    held = [f.position_deg for f in drives.feedback()]
    assert [f.state for f in drives.feedback()] == [DriveState.QUICK_STOP_ACTIVE] * 2
    tick(drives, rig, q=(40.0, 40.0), n=50)
    assert [f.position_deg for f in drives.feedback()] == pytest.approx(held, abs=0.2)
    drives.enable()
    tick(drives, rig, q=(40.0, 40.0), n=200)
    assert [f.position_deg for f in drives.feedback()] == pytest.approx([40.0, 40.0], abs=0.01)


def test_halt_stops_motion_and_release_follows_again(enabled):
    drives, rig = enabled
    drives.halt(True)
    tick(drives, rig, q=(20.0, 20.0), n=50)
    assert [f.position_deg for f in drives.feedback()] == pytest.approx([0.0, 0.0], abs=0.01)
    drives.halt(False)
    tick(drives, rig, q=(20.0, 20.0), n=200)
    assert [f.position_deg for f in drives.feedback()] == pytest.approx([20.0, 20.0], abs=0.01)


def test_disable_reaches_switch_on_disabled(enabled):
    drives, _rig = enabled
    drives.disable()
    assert [f.state for f in drives.feedback()] == [DriveState.SWITCH_ON_DISABLED] * 2


def test_corrupt_tpdo_is_reported_naming_drive_and_mapping(enabled):
    drives, rig = enabled
    rig.inject_fault("corrupt", drive=1)
    tick(drives, rig)
    (event,) = drives.poll_events()
    assert event.kind is FaultKind.BUS_ERROR and event.drive == 1
    assert "malformed TPDO1 0x182 with 5 bytes" in event.message
    assert drives.feedback()[1].age_syncs == 1


def test_unknown_frame_is_reported_once_with_its_cob_id(enabled):
    drives, rig = enabled
    rig.inject_fault("frame", can_id=0x123, data=b"\x01\x02")
    rig.inject_fault("frame", can_id=0x123, data=b"\x01\x02")
    tick(drives, rig)
    (event,) = drives.poll_events()
    assert event.kind is FaultKind.BUS_ERROR
    assert "0x123" in event.message and "2 bytes" in event.message


def test_sdo_abort_names_drive_object_and_abort_meaning(enabled):
    drives, _ = enabled
    with pytest.raises(DriveError, match=r"drive 0 \(node 1\): SDO download 0x1018:01 aborted "
                                         r"with 0x06010002: attempt to write a read only object"):
        drives.sdo_write(0, 0x1018, 1, 5)
    with pytest.raises(DriveError, match=r"0x2000:00 aborted with 0x06020000: object does not "
                                         r"exist"):
        drives.sdo_upload(1, 0x2000, 0)
    with pytest.raises(DriveError, match=r"0x6060:00 aborted with 0x06090030"):
        drives.sdo_write(0, 0x6060, 0, 1)  # profile position mode is not supported


def test_identity_mismatch_fails_boot_with_both_identities():
    channel = "identity-mismatch"
    rig = SimRig(LockstepBus(channel), SpringPlant(),
                 [DriveConfig(node_id=1, vendor_id=0x1234), DriveConfig(node_id=2)], PERIOD_S)
    drives = CanOpenDrives(LockstepBus(channel),
                           [DriveConfig(node_id=1, vendor_id=0x9999), DriveConfig(node_id=2)],
                           PERIOD_S, clock=rig.clock, idle=rig.exchange, own_bus=True)
    try:
        with pytest.raises(DriveError, match=r"drive 0 \(node 1\): boot failed: identity 0x1018 "
                                             r"is vendor 0x00001234.*expects vendor 0x00009999"):
            drives.boot()
        assert [e.kind for e in drives.poll_events()] == [FaultKind.BOOT_FAILED]
    finally:
        drives.close()
        rig.close()


def test_missing_drive_fails_boot_naming_it():
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S)
    rig.inject_fault("silent", drive=1)
    try:
        with pytest.raises(DriveError, match=r"drive 1 \(node 2\): boot failed: no boot-up"):
            drives.boot()
    finally:
        drives.close()
        rig.close()


class _FailingBus(can.BusABC):
    """A bus whose receive fails after a few calls, like a CAN adapter unplugged."""

    def __init__(self, fail_after: int) -> None:
        super().__init__(channel="failing")
        self._left = fail_after

    def send(self, msg: can.Message, timeout: float | None = None) -> None:
        raise can.CanOperationError("Network is down")

    def _recv_internal(self, timeout: float | None):
        self._left -= 1
        if self._left < 0:
            raise can.CanOperationError("adapter unplugged")
        time.sleep(0.001)
        return None, False


def test_notifier_error_becomes_a_bus_error_event():
    bus = _FailingBus(fail_after=3)
    drives = CanOpenDrives(bus, [DriveConfig(node_id=1)], PERIOD_S, receive="notifier")
    try:
        deadline = time.monotonic() + 5.0
        events = []
        while not events and time.monotonic() < deadline:
            time.sleep(0.01)
            drives.pump()
            events = drives.poll_events()
        assert events and events[0].kind is FaultKind.BUS_ERROR
        assert "receive failed in the notifier: adapter unplugged" in events[0].message
        time.sleep(0.1)  # the adapter keeps failing: still one event for the whole run
        drives.pump()
        assert drives.poll_events() == []
    finally:
        drives.close()
        bus.shutdown()


def test_send_error_becomes_one_bus_error_event_not_an_exception():
    bus = _FailingBus(fail_after=10**9)
    drives = CanOpenDrives(bus, [DriveConfig(node_id=1)], PERIOD_S)
    try:
        for _ in range(3):
            drives.write_targets([1.0])
            drives.sync()
        events = drives.poll_events()
        assert len(events) == 1 and events[0].kind is FaultKind.BUS_ERROR
        assert "send of 0x201 failed: Network is down" in events[0].message
    finally:
        drives.close()
        bus.shutdown()


def test_non_finite_target_is_refused(enabled):
    drives, _ = enabled
    with pytest.raises(DriveError, match=r"drive 1 \(node 2\): target nan deg"):
        drives.write_targets([0.0, float("nan")])


def test_rpdo_of_the_wrong_length_makes_the_drive_send_emcy_8210(enabled):
    drives, rig = enabled
    drives.bus.send(can.Message(arbitration_id=0x201, data=b"\x0f\x00\x00", is_extended_id=False))
    tick(drives, rig)
    (event,) = drives.poll_events()
    assert event.kind is FaultKind.EMCY and event.code == 0x8210 and event.drive == 0
    assert "PDO not processed due to length error" in event.message


def test_drive_leaving_operational_is_a_drive_fault(enabled):
    drives, rig = enabled
    drives.bus.send(can.Message(arbitration_id=0x000, data=b"\x02\x02", is_extended_id=False))
    _, event = run_until(drives, rig, FaultKind.DRIVE_FAULT, 20)  # next heartbeat, <= 50 ms
    assert event.drive == 1
    assert "left OPERATIONAL, NMT state is now STOPPED" in event.message


def test_rated_current_mismatch_fails_boot_naming_both_values():
    channel = "rated-current-mismatch"
    rig = SimRig(LockstepBus(channel), SpringPlant(),
                 [DriveConfig(node_id=1), DriveConfig(node_id=2)], PERIOD_S)
    drives = CanOpenDrives(LockstepBus(channel),
                           [DriveConfig(node_id=1), DriveConfig(node_id=2, current_scale_A=0.001)],
                           PERIOD_S, clock=rig.clock, idle=rig.exchange, own_bus=True)
    try:
        with pytest.raises(DriveError, match=r"drive 1 \(node 2\): boot failed: motor rated "
                                             r"current 0x6075 is 2000 mA but "
                                             r"current_scale_A=0.001 implies 1000 mA"):
            drives.boot()
    finally:
        drives.close()
        rig.close()


def test_sdo_abort_during_boot_is_a_boot_failure_naming_the_object():
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S)
    rig.nodes[1].od[0x6065].max = 10  # this drive refuses any realistic following error window
    try:
        with pytest.raises(DriveError, match=r"drive 1 \(node 2\): boot failed: SDO download "
                                             r"0x6065:00 aborted with 0x06090031: value of "
                                             r"parameter written too high"):
            drives.boot()
        assert FaultKind.BOOT_FAILED in {e.kind for e in drives.poll_events()}
    finally:
        drives.close()
        rig.close()


def test_the_split_modules_are_one_master_behind_the_old_import_path() -> None:
    assert issubclass(CanOpenDrives, MasterHoming)
    assert canopen_master.MAX_PENDING_BUS_EVENTS == MAX_PENDING_BUS_EVENTS
