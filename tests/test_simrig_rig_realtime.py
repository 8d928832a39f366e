"""Real-time mode: the rig serves python-can's virtual bus from a thread, the master uses a
notifier. Only behaviour is checked here, never timing (that is `tsmd bench bus`)."""

from __future__ import annotations

import time

import numpy as np
from support.plants import SpringPlant

from drivers.drive import DriveState
from simrig.rig import open_sim_rig

PERIOD_S = 0.004


def test_real_time_rig_boots_enables_and_follows_targets():
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S, seed=2, lockstep=False)
    try:
        drives.boot()
        drives.enable()
        assert [f.state for f in drives.feedback()] == [DriveState.OPERATION_ENABLED] * 2
        deadline = time.monotonic()
        for _ in range(150):
            drives.write_targets([8.0, -8.0])
            drives.sync()
            deadline += PERIOD_S
            time.sleep(max(0.0, deadline - time.monotonic()))
            drives.pump()
        positions = [f.position_deg for f in drives.feedback()]
        assert np.allclose(positions, [8.0, -8.0], atol=0.05)
        drives.disable()
        assert [f.state for f in drives.feedback()] == [DriveState.SWITCH_ON_DISABLED] * 2
    finally:
        drives.close()
        rig.close()
