"""canopen's own BaseNode402 (an independent CiA 402 implementation) drives a simulated drive.

Real time on python-can's virtual bus: the rig serves frames from its thread, canopen runs its
notifier, SYNC producer and periodic RPDO.
"""

from __future__ import annotations

import itertools

import can
import canopen
import pytest
from canopen.profiles.p402 import BaseNode402
from support.plants import SpringPlant

from drivers.od import EDS_PATH
from drivers.units import DriveConfig
from simrig.rig import SimRig

PERIOD_S = 0.01
_CHANNEL = itertools.count()


@pytest.fixture()
def canopen_node():
    channel = f"tsmd-402-{next(_CHANNEL)}"

    rig = SimRig(can.Bus(interface="virtual", channel=channel), SpringPlant(),
                 [DriveConfig(node_id=1), DriveConfig(node_id=2)], PERIOD_S, lockstep=False)
    rig.start()
    network = canopen.Network()
    network.connect(interface="virtual", channel=channel)
    node = BaseNode402(1, canopen.import_od(str(EDS_PATH), 1))
    network.add_node(node)
    yield network, node, rig
    network.sync.stop()
    for pdo in node.rpdo.values():
        pdo.stop()
    network.disconnect()
    rig.close()


def test_base_node_402_enables_reads_pdos_and_disables(canopen_node):
    network, node, rig = canopen_node
    node.nmt.state = "PRE-OPERATIONAL"
    node.setup_402_state_machine()
    assert node.tpdo[1].enabled and node.rpdo[1].enabled
    node.sdo[0x6060].raw = 8
    assert node.op_mode == "CYCLIC SYNCHRONOUS POSITION"
    node.nmt.state = "OPERATIONAL"
    node.rpdo[1]["Controlword"].raw = 0
    node.rpdo[1]["Target position"].raw = 0
    node.rpdo[1].start(PERIOD_S)
    network.sync.start(PERIOD_S)
    node.tpdo[1].wait_for_reception(1.0)
    assert node.state == "SWITCH ON DISABLED"

    node.state = "OPERATION ENABLED"
    assert node.state == "OPERATION ENABLED"

    counts_per_deg = DriveConfig(node_id=1).counts_per_deg
    target = round(10.0 * counts_per_deg)
    node.rpdo[1]["Target position"].raw = target
    node.rpdo[1].update()
    for _ in range(200):
        node.tpdo[1].wait_for_reception(1.0)
        if abs(node.tpdo[1]["Position actual value"].raw - target) < 10:
            break
    position = node.tpdo[1]["Position actual value"].raw
    assert abs(position - target) < 10
    assert abs(position - rig.knob_deg()[0] * counts_per_deg) < 0.5 * counts_per_deg
    # spring load 0.02 Nm at 10 deg -> a positive holding current (raw: 1/1000 of rated current)
    node.tpdo[1].wait_for_reception(1.0)
    assert node.tpdo[1]["Current actual value"].raw > 0
    assert node.sdo[0x6064].raw == pytest.approx(position, abs=50)

    node.state = "SWITCH ON DISABLED"
    assert node.state == "SWITCH ON DISABLED"
