"""Arbitrary frames on the bus never crash the master or the simulated drive: they become
events (master) or are ignored / answered with an SDO abort (drive)."""

from __future__ import annotations

import can
from drive_support import SpringPlant
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from drivers.drive import DriveError, FaultKind
from simrig.rig import open_sim_rig

PERIOD_S = 0.004
frames = st.lists(st.tuples(st.integers(0, 0x7FF), st.binary(max_size=8)), min_size=1,
                  max_size=6)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(frames)
def test_random_frames_to_the_master_become_events_never_exceptions(batch):
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S)
    try:
        drives.boot()
        drives.enable()
        drives.poll_events()
        for can_id, data in batch:
            rig.inject_fault("frame", can_id=can_id, data=data)
        for _ in range(3):
            drives.write_targets([1.0, 1.0])
            drives.sync()
            rig.exchange()
            drives.pump()
        kinds = {e.kind for e in drives.poll_events()}
        # a forged boot-up frame (0x701/0x702, data 0x00) looks exactly like a reboot
        assert kinds <= {FaultKind.BUS_ERROR, FaultKind.EMCY, FaultKind.DRIVE_FAULT,
                         FaultKind.STALE_FEEDBACK, FaultKind.DRIVE_REBOOTED}
        assert len(drives.feedback()) == 2
    finally:
        drives.close()
        rig.close()


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(frames)
def test_random_frames_to_the_drives_never_crash_the_rig(batch):
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S)
    try:
        drives.boot()
        for can_id, data in batch:
            drives.bus.send(can.Message(arbitration_id=can_id, data=data, is_extended_id=False))
        for _ in range(3):
            rig.exchange()
        drives.pump()
        # whatever happened (even an NMT reset), the master can boot the drives again
        drives.boot()
        drives.enable()
    except DriveError as exc:  # e.g. a random NMT "stop" addressed the node mid-boot
        raise AssertionError(f"drives did not recover: {exc}") from exc
    finally:
        drives.close()
        rig.close()


def test_enable_with_a_silent_drive_times_out_naming_it():
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S)
    try:
        drives.boot()
        rig.inject_fault("silent", drive=0)
        try:
            drives.enable()
        except DriveError as exc:
            assert "drive 0 (node 1): enable timed out after 0.5 s" in str(exc)
        else:
            raise AssertionError("enable() succeeded with a silent drive")
        assert FaultKind.STATE_TIMEOUT in {e.kind for e in drives.poll_events()}
    finally:
        drives.close()
        rig.close()
