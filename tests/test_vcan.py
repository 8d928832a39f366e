"""SocketCAN vcan: the master and the simulated rig on a real kernel CAN interface.

Runs where ``vcan0`` exists (``ip link add dev vcan0 type vcan && ip link set up vcan0``);
skips with the reason everywhere else.
"""

from __future__ import annotations

import os
import socket

import numpy as np
import pytest
from drive_support import SpringPlant

VCAN = os.environ.get("TSMD_VCAN", "vcan0")


def _vcan_missing() -> str | None:
    if not hasattr(socket, "AF_CAN"):
        return "this Python/OS has no socket.AF_CAN (SocketCAN is Linux only)"
    if not os.path.exists(f"/sys/class/net/{VCAN}"):
        return f"no network interface {VCAN!r} (create it with: ip link add dev {VCAN} type vcan)"
    try:
        with open(f"/sys/class/net/{VCAN}/operstate") as f:
            state = f.read().strip()
    except OSError as exc:
        return f"cannot read the state of {VCAN}: {exc}"
    if state not in ("up", "unknown"):
        return f"{VCAN} is {state}, not up (ip link set up {VCAN})"
    try:
        s = socket.socket(socket.AF_CAN, socket.SOCK_RAW, socket.CAN_RAW)
        s.bind((VCAN,))
        s.close()
    except OSError as exc:
        return f"cannot bind a CAN_RAW socket to {VCAN}: {exc}"
    return None


needs_vcan = pytest.mark.skipif(_vcan_missing() is not None, reason=str(_vcan_missing()))
pytestmark = [pytest.mark.vcan]


@needs_vcan
def test_master_boots_and_streams_to_the_rig_over_vcan():
    import time

    import can

    from drivers.canopen_master import CanOpenDrives
    from drivers.drive import DriveState
    from simrig.rig import SimRig, default_drive_configs

    period_s = 0.004
    configs = default_drive_configs()
    rig = SimRig(can.Bus(interface="socketcan", channel=VCAN), SpringPlant(), configs, period_s,
                 lockstep=False)
    rig.start()
    drives = CanOpenDrives(can.Bus(interface="socketcan", channel=VCAN), configs, period_s,
                           receive="notifier", own_bus=True)
    try:
        drives.boot()
        drives.enable()
        deadline = time.monotonic()
        for _ in range(250):
            drives.write_targets([10.0, -10.0])
            drives.sync()
            deadline += period_s
            time.sleep(max(0.0, deadline - time.monotonic()))
            drives.pump()
        fb = drives.feedback()
        assert [f.state for f in fb] == [DriveState.OPERATION_ENABLED] * 2
        assert np.allclose([f.position_deg for f in fb], [10.0, -10.0], atol=0.05)
        assert drives.poll_events() == []
    finally:
        drives.close()
        rig.close()


def _real_time_pair(interface: str, configs):
    import can

    from drivers.canopen_master import CanOpenDrives
    from simrig.rig import SimRig

    period_s = 0.004
    channel = VCAN if interface == "socketcan" else f"tsmd-rt-{os.getpid()}"
    rig = SimRig(can.Bus(interface=interface, channel=channel), SpringPlant(), configs, period_s,
                 lockstep=False)
    rig.start()
    drives = CanOpenDrives(can.Bus(interface=interface, channel=channel), configs, period_s,
                           receive="notifier", own_bus=True)
    return drives, rig


def _stream(drives, q, ticks: int, period_s: float = 0.004) -> list:
    import time

    events = []
    deadline = time.monotonic()
    for _ in range(ticks):
        drives.write_targets(q)
        drives.sync()
        deadline += period_s
        time.sleep(max(0.0, deadline - time.monotonic()))
        drives.pump()
        events += drives.poll_events()
    return events


@pytest.mark.parametrize("interface", [
    "virtual", pytest.param("socketcan", marks=needs_vcan)])
def test_homing_then_reboot_and_recovery_in_real_time(interface):
    from drivers.drive import FaultKind
    from drivers.units import DriveConfig, HomingConfig

    configs = [DriveConfig(node_id=1, homing=HomingConfig(method=37, home_offset_deg=2.0,
                                                          required=True)),
               DriveConfig(node_id=2)]
    drives, rig = _real_time_pair(interface, configs)
    try:
        drives.boot()
        assert not drives.zero_referenced()
        assert drives.home()[0].homed
        _stream(drives, [0.0, 0.0], 3)
        assert drives.feedback()[0].position_deg == pytest.approx(-2.0, abs=0.01)
        drives.enable()
        _stream(drives, [3.0, 3.0], 100)
        rig.inject_fault("reboot", drive=1)
        events = _stream(drives, [3.0, 3.0], 50)
        assert FaultKind.DRIVE_REBOOTED in {e.kind for e in events}
        drives.fault_reset()
        drives.disable()
        drives.enable()
        _stream(drives, [3.0, 6.0], 150)
        fb = drives.feedback()
        assert np.allclose([f.position_deg for f in fb], [3.0, 6.0], atol=0.05)
    finally:
        drives.close()
        rig.close()


@needs_vcan
def test_error_frames_sent_on_vcan_become_bus_events():
    import can

    from drivers.can_errors import CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE, BusState, error_frame
    from simrig.rig import default_drive_configs

    drives, rig = _real_time_pair("socketcan", default_drive_configs())
    sender = can.Bus(interface="socketcan", channel=VCAN)
    try:
        drives.boot()
        sender.send(error_frame(CAN_ERR_CRTL, bytes((0, CAN_ERR_CRTL_TX_PASSIVE))))
        _stream(drives, [0.0, 0.0], 10)
        assert drives.bus_state is BusState.ERROR_PASSIVE
        assert drives.poll_bus_events()
    finally:
        sender.shutdown()
        drives.close()
        rig.close()
