"""CAN bus faults, drive reboots and timeouts, on the simulated rig (lockstep bus)."""

from __future__ import annotations

import pytest
from support.drives import open_enabled_rig, tick
from support.plants import SpringPlant

from drivers import can_errors as ce
from drivers.can_errors import BusState, decode_error_frame, error_frame
from drivers.drive import DriveError, DriveState, DriveUnreachableError, FaultKind
from drivers.units import DriveConfigError, MasterTimeouts
from simrig.rig import open_sim_rig

PERIOD_S = 0.004


@pytest.fixture()
def enabled():
    drives, rig = open_enabled_rig(2, PERIOD_S)
    yield drives, rig
    drives.close()
    rig.close()


# --- error frames ----------------------------------------------------------------------------

def test_error_passive_frame_is_decoded_with_its_counters():
    report = decode_error_frame(error_frame(ce.CAN_ERR_CRTL | ce.CAN_ERR_CNT,
                                            bytes((0, ce.CAN_ERR_CRTL_TX_PASSIVE, 0, 0, 0, 0,
                                                   130, 5))))
    assert report.state is BusState.ERROR_PASSIVE
    assert report.details == ("TX error passive",)
    assert (report.tx_errors, report.rx_errors) == (130, 5)
    assert report.text() == "controller problem (TX error passive), error counters TX 130 RX 5"


@pytest.mark.parametrize(("classes", "data", "words"), [
    (ce.CAN_ERR_BUSOFF, b"", "bus-off"),
    (ce.CAN_ERR_RESTARTED, b"", "controller restarted"),
    (ce.CAN_ERR_PROT | ce.CAN_ERR_BUSERROR, bytes((0, 0, 0x04, 0x19)),
     "protocol violation, bus error (bit stuffing error, at location 0x19)"),
    (ce.CAN_ERR_TRX, bytes((0, 0, 0, 0, 0x70)), "transceiver problem (CANL short to GND)"),
    (ce.CAN_ERR_LOSTARB, bytes((3,)), "lost arbitration (arbitration lost at bit 3)"),
    (ce.CAN_ERR_ACK, b"", "no ACK on transmission"),
    (ce.CAN_ERR_CRTL, bytes((0, ce.CAN_ERR_CRTL_RX_WARNING)), "RX error warning level"),
])
def test_each_error_class_is_named(classes, data, words):
    assert words in decode_error_frame(error_frame(classes, data)).text()


def test_controller_warnings_are_bus_events_not_faults(enabled):
    drives, rig = enabled
    rig.inject_fault("error_frame", classes=ce.CAN_ERR_CRTL,
                     data=bytes((0, ce.CAN_ERR_CRTL_TX_WARNING, 0, 0, 0, 0, 97, 0)))
    tick(drives, rig)
    assert drives.poll_events() == []
    (event,) = drives.poll_bus_events()
    assert "TX error warning level" in event.message
    assert drives.bus_state is BusState.ERROR_WARNING
    rig.inject_fault("error_frame", classes=ce.CAN_ERR_CRTL,
                     data=bytes((0, ce.CAN_ERR_CRTL_ACTIVE)))
    tick(drives, rig)
    assert drives.bus_state is BusState.ERROR_ACTIVE


def test_a_flood_of_error_frames_keeps_a_bounded_backlog(enabled):
    drives, rig = enabled
    for _ in range(1000):
        rig.inject_fault("error_frame", classes=ce.CAN_ERR_PROT | ce.CAN_ERR_BUSERROR)
    tick(drives, rig)
    assert len(drives.poll_bus_events()) == 256
    assert drives.bus_events_dropped == 1000 - 256


# --- bus-off and restart ---------------------------------------------------------------------

def test_bus_off_is_a_fault_at_the_next_pump(enabled):
    drives, rig = enabled
    rig.inject_fault("bus_off")
    drives.pump()
    (event,) = drives.poll_events()
    assert event.kind is FaultKind.BUS_OFF and event.drive == -1
    assert "bus-off" in event.message and drives.bus_state is BusState.BUS_OFF


def test_drives_stop_by_themselves_while_the_master_is_bus_off(enabled):
    drives, rig = enabled
    tick(drives, rig, (10.0, 10.0), 100)
    rig.inject_fault("bus_off")
    tick(drives, rig, (40.0, 40.0), 150)  # nothing reaches the drives: 0.6 s
    assert [n.state for n in rig.nodes] == [DriveState.QUICK_STOP_ACTIVE] * 2
    stopped = rig.knob_deg()
    tick(drives, rig, (40.0, 40.0), 50)
    assert rig.knob_deg() == pytest.approx(stopped)


def test_reset_is_refused_until_the_interface_restarts_then_recovers(enabled):
    drives, rig = enabled
    rig.inject_fault("bus_off")
    tick(drives, rig, n=60)
    with pytest.raises(DriveUnreachableError, match="bus-off"):
        drives.fault_reset()
    rig.inject_fault("bus_restart")
    tick(drives, rig, n=30)
    assert drives.bus_state is BusState.ERROR_ACTIVE
    restarted = [e for e in drives.poll_bus_events() if e.report.restarted]
    assert restarted
    drives.poll_events()
    drives.fault_reset()
    drives.disable()
    drives.enable()
    tick(drives, rig, (5.0, -5.0), 200)
    assert [f.position_deg for f in drives.feedback()] == pytest.approx([5.0, -5.0], abs=0.05)


# --- drive reboot ----------------------------------------------------------------------------

def test_a_reboot_is_reported_naming_the_drive(enabled):
    drives, rig = enabled
    rig.inject_fault("reboot", drive=1)
    tick(drives, rig)
    events = drives.poll_events()
    assert [e.kind for e in events] == [FaultKind.DRIVE_REBOOTED]
    assert events[0].drive == 1 and "drive 1 (node 2): rebooted" in events[0].message


def test_a_rebooted_drive_never_moves_until_reset_and_enable(enabled):
    drives, rig = enabled
    rig.inject_fault("reboot", drive=1)
    tick(drives, rig, (0.0, 20.0), 200)
    assert rig.knob_deg()[1] == pytest.approx(0.0, abs=1e-6)
    # reported once, with no stale-feedback or heartbeat noise after it
    assert [e.kind for e in drives.poll_events()] == [FaultKind.DRIVE_REBOOTED]
    drives.fault_reset()
    tick(drives, rig, (0.0, 20.0), 50)
    assert rig.nodes[1].state is DriveState.SWITCH_ON_DISABLED
    assert rig.knob_deg()[1] == pytest.approx(0.0, abs=1e-6)
    assert drives.feedback()[1].age_syncs == 0  # PDO mapping re-configured
    drives.enable()
    tick(drives, rig, (0.0, 20.0), 250)
    assert rig.knob_deg()[1] == pytest.approx(20.0, abs=0.1)
    assert drives.poll_events() == []


# --- timeouts --------------------------------------------------------------------------------

def test_timeouts_are_validated_naming_the_key():
    with pytest.raises(DriveConfigError, match="timeouts.enable_s"):
        MasterTimeouts(enable_s=0.0)
    with pytest.raises(DriveConfigError, match="unknown timeout"):
        MasterTimeouts.from_dict({"enable": 1.0})


def test_a_transition_timeout_names_drive_transition_and_statusword():
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S,
                               timeouts=MasterTimeouts(enable_s=0.2))
    try:
        drives.boot()
        rig.nodes[0].write_controlword = lambda cw: None  # a drive that ignores commands
        t0 = rig.clock.now_s()
        with pytest.raises(DriveError, match=r"drive 0 \(node 1\): enable timed out after 0.2 s "
                                             r"in state SWITCH ON DISABLED \(statusword 0x0240"):
            drives.enable()
        assert rig.clock.now_s() - t0 == pytest.approx(0.2, abs=0.02)
        assert FaultKind.STATE_TIMEOUT in {e.kind for e in drives.poll_events()}
    finally:
        drives.close()
        rig.close()


def test_a_silent_drive_is_named_as_silent_not_as_a_timed_out_transition(enabled):
    drives, rig = enabled
    rig.inject_fault("silent", drive=1)
    with pytest.raises(DriveUnreachableError, match=r"drive 1 \(node 2\) silent"):
        drives.disable()


def test_reset_of_a_silent_drive_is_a_fault_class_error(enabled):
    drives, rig = enabled
    rig.inject_fault("silent", drive=0)
    tick(drives, rig, n=60)  # heartbeat timeout 150 ms
    with pytest.raises(DriveUnreachableError,
                       match=r"drive 0 \(node 1\) silent: no heartbeat for .* and no TPDO"):
        drives.fault_reset()


def test_sdo_and_boot_timeouts_are_configurable():
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S,
                               timeouts=MasterTimeouts(sdo_s=0.1, boot_s=0.3))
    try:
        rig.inject_fault("silent", drive=1)
        t0 = rig.clock.now_s()
        with pytest.raises(DriveError, match=r"drive 1 \(node 2\): boot failed: no boot-up "
                                             r"message after NMT reset node within 0.3 s"):
            drives.boot()
        assert rig.clock.now_s() - t0 == pytest.approx(0.3, abs=0.02)
        t0 = rig.clock.now_s()
        with pytest.raises(DriveError, match=r"SDO upload 0x1000:00 timed out after 0.1 s"):
            drives.sdo_read(1, 0x1000)
        assert rig.clock.now_s() - t0 == pytest.approx(0.1, abs=0.02)
    finally:
        drives.close()
        rig.close()


def test_reset_of_a_drive_without_heartbeat_says_its_tpdos_still_arrive(enabled):
    drives, rig = enabled
    rig.inject_fault("heartbeat_stop", drive=1)
    tick(drives, rig, n=60)
    with pytest.raises(DriveUnreachableError, match=r"drive 1 \(node 2\) sends no heartbeat "
                                                    r"for .* \(its TPDOs arrive\)"):
        drives.fault_reset()
