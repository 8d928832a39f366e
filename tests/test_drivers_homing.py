"""Homing (CiA 402 Homing Mode) on the simulated rig: each method finds its reference."""

from __future__ import annotations

import pytest
from drive_support import SpringPlant

from drivers.drive import DriveError, DriveState
from drivers.units import DriveConfig, DriveConfigError, HomingConfig
from simrig.rig import open_sim_rig

PERIOD_S = 0.004


def rig_with(homing: HomingConfig, seed: int = 3):
    configs = [DriveConfig(node_id=1, homing=homing), DriveConfig(node_id=2)]
    drives, rig = open_sim_rig(SpringPlant(), configs, PERIOD_S, seed=seed)
    drives.boot()
    return drives, rig


def tick(drives, rig, q, n: int) -> None:
    for _ in range(n):
        drives.write_targets(q)
        drives.sync()
        rig.exchange()
        drives.pump()


def move_to(drives, rig, q, ticks: int = 300) -> None:
    drives.enable()
    tick(drives, rig, q, ticks)
    drives.disable()


def test_a_drive_without_a_homing_method_is_skipped_and_needs_no_reference():
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S)
    try:
        drives.boot()
        status = drives.home()
        assert [s.method for s in status] == ["none", "none"]
        assert not any(s.homed for s in status)
        assert drives.zero_referenced()
        assert rig.nodes[0].mode_display == 8  # never put in Homing Mode (6)
    finally:
        drives.close()
        rig.close()


def test_current_position_method_makes_here_read_minus_the_home_offset():
    drives, rig = rig_with(HomingConfig(method=37, home_offset_deg=5.0, required=True))
    try:
        move_to(drives, rig, (20.0, 0.0))
        assert not drives.zero_referenced()
        status = drives.home()
        assert status[0].homed and status[0].method == "current_position"
        assert drives.zero_referenced()
        tick(drives, rig, (0.0, 0.0), 3)
        fb = drives.feedback()[0]
        assert fb.position_deg == pytest.approx(-5.0, abs=0.01)
        assert rig.knob_deg()[0] == pytest.approx(20.0, abs=0.1)  # nothing moved
        assert fb.state is DriveState.SWITCH_ON_DISABLED
        assert rig.nodes[0].mode_display == 8  # back in CSP
    finally:
        drives.close()
        rig.close()


def test_the_older_method_number_35_is_accepted_for_current_position():
    drives, rig = rig_with(HomingConfig(method=35))
    try:
        assert drives.home()[0].homed
    finally:
        drives.close()
        rig.close()


@pytest.mark.parametrize(("method", "stop_deg", "offset_deg"), [
    ("hard_stop_negative", -40.0, 40.0), ("hard_stop_positive", 30.0, -30.0)])
def test_hard_stop_method_finds_the_stop_by_the_motor_current(method, stop_deg, offset_deg):
    drives, rig = rig_with(HomingConfig.from_dict(
        {"method": method, "home_offset_deg": offset_deg, "switch_speed_deg_s": 20.0,
         "current_threshold_A": 0.3, "timeout_s": 10.0}))
    try:
        rig.motors[0].travel_deg = (-40.0, 30.0)
        move_to(drives, rig, (7.0, 0.0))  # somewhere unknown to the master
        drives.home([0])
        tick(drives, rig, (0.0, 0.0), 3)
        # the stop reads -offset: the knob zero is the mechanical straight position again
        assert drives.feedback()[0].position_deg == pytest.approx(stop_deg, abs=0.5)
        assert drives.feedback()[0].position_deg == pytest.approx(rig.knob_deg()[0], abs=0.5)
    finally:
        drives.close()
        rig.close()


def test_index_method_homes_on_the_next_index_pulse():
    drives, rig = rig_with(HomingConfig(method=34, zero_speed_deg_s=2.0, timeout_s=10.0))
    try:
        pitch = 360.0 / rig.motors[0].gear_ratio
        rig.nodes[0].index_phase_deg = 0.3 * pitch
        assert drives.home([0])[0].homed
        tick(drives, rig, (0.0, 0.0), 3)
        assert drives.feedback()[0].position_deg == pytest.approx(
            rig.knob_deg()[0] - 0.3 * pitch, abs=0.01)
        assert 0.3 * pitch <= rig.knob_deg()[0] < 0.3 * pitch + 0.2
    finally:
        drives.close()
        rig.close()


def test_a_hard_stop_that_is_never_reached_times_out_naming_drive_and_method():
    drives, rig = rig_with(HomingConfig(method=-3, switch_speed_deg_s=20.0, timeout_s=0.5))
    try:
        with pytest.raises(DriveError, match=r"drive 0 \(node 1\): homing \(hard_stop_positive,"
                                             r" method -3\) timed out after 0.5 s \(statusword"):
            drives.home()
        assert not drives.homing_status()[0].homed
        tick(drives, rig, (0.0, 0.0), 3)
        assert drives.feedback()[0].state is DriveState.SWITCH_ON_DISABLED
        assert rig.nodes[0].mode_display == 8
    finally:
        drives.close()
        rig.close()


def test_homing_is_lost_when_the_drive_reboots():
    drives, rig = rig_with(HomingConfig(method=37, required=True))
    try:
        drives.home()
        rig.inject_fault("reboot", 0)
        tick(drives, rig, (0.0, 0.0), 2)
        assert not drives.homing_status()[0].homed
        assert not drives.zero_referenced()
    finally:
        drives.close()
        rig.close()


def test_a_rebooted_drive_reads_zero_where_it_stopped():
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S)
    try:
        drives.boot()
        move_to(drives, rig, (12.0, 0.0))
        rig.inject_fault("reboot", 0)
        tick(drives, rig, (0.0, 0.0), 2)
        drives.fault_reset()
        tick(drives, rig, (0.0, 0.0), 3)
        assert drives.feedback()[0].position_deg == pytest.approx(0.0, abs=0.01)
        assert rig.knob_deg()[0] == pytest.approx(12.0, abs=0.1)
    finally:
        drives.close()
        rig.close()


@pytest.mark.parametrize(("entry", "key"), [
    ({"method": "spiral"}, "homing.method"),
    ({"method": 36}, "homing.method"),
    ({"required": True}, "homing.required"),
    ({"method": 37, "timeout_s": 0}, "homing.timeout_s"),
    ({"method": 37, "speed": 1}, "homing key"),
])
def test_invalid_homing_config_names_the_key(entry, key):
    with pytest.raises(DriveConfigError, match=key):
        DriveConfig.from_dict({"node_id": 1, "homing": entry})


def test_homing_config_reads_method_names():
    config = DriveConfig.from_dict({"node_id": 1, "homing": {"method": "current_position",
                                                             "required": True}})
    assert config.homing.method == 37 and config.homing.required


def test_a_following_error_at_the_stop_fails_homing_naming_the_fault():
    drives, rig = rig_with(HomingConfig(method=-4, switch_speed_deg_s=20.0,
                                        current_threshold_A=2.9, timeout_s=5.0))
    try:
        rig.motors[0].travel_deg = (-10.0, 10.0)
        with pytest.raises(DriveError, match=r"drive 0 \(node 1\): homing \(hard_stop_negative, "
                                             r"method -4\) stopped: the drive is in FAULT"):
            drives.home()
        assert not rig.nodes[0].homing.active  # never resumes on its own
        assert rig.nodes[0].mode_display == 8
    finally:
        drives.close()
        rig.close()


def test_a_drive_in_fault_is_not_homed():
    drives, rig = rig_with(HomingConfig(method=37))
    try:
        rig.inject_fault("emcy", 0)
        tick(drives, rig, (0.0, 0.0), 40)
        with pytest.raises(DriveError, match=r"cannot home, drive is in FAULT"):
            drives.home()
    finally:
        drives.close()
        rig.close()
