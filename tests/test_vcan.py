"""SocketCAN vcan: the master and the simulated rig on a real kernel CAN interface.

Runs where ``vcan0`` exists (``ip link add dev vcan0 type vcan && ip link set up vcan0``);
skips with the reason everywhere else.
"""

from __future__ import annotations

import os
import socket
import time

import can
import numpy as np
import pytest
from support.plants import SpringPlant

from drivers.canopen_master import CanOpenDrives
from drivers.drive import DriveState
from simrig.rig import SimRig, default_drive_configs

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


pytestmark = [pytest.mark.vcan,
              pytest.mark.skipif(_vcan_missing() is not None, reason=str(_vcan_missing()))]


def test_master_boots_and_streams_to_the_rig_over_vcan():
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
