"""Real-time mode: the rig serves python-can's virtual bus from a thread, the master uses a
notifier. Only behaviour is checked here, never timing (that is `tsmd bench bus`)."""

from __future__ import annotations

import itertools
import time

import can
import numpy as np
import pytest
from support.plants import SpringPlant

from drivers.canopen_master import CanOpenDrives
from drivers.clock import SimClock
from drivers.drive import DriveState
from simrig.plant import PlantStep
from simrig.rig import SimRig, default_drive_configs, open_sim_rig

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


# -- the physics keeps the rig's clock (an injected fake clock: no timing in the asserts) -----

SYNC = can.Message(arbitration_id=0x080, data=b"", is_extended_id=False)
_CHANNELS = itertools.count()


class TimedSpring(SpringPlant):
    """The spring plant, adding up the time it is stepped through."""

    def __init__(self) -> None:
        super().__init__()
        self.time_s = 0.0

    def step(self, dt_s: float, knob_deg: np.ndarray) -> PlantStep:
        self.time_s += dt_s
        return super().step(dt_s, knob_deg)


@pytest.fixture()
def fake_clock_rig():
    """A real-time rig on a fake clock, served by hand (no thread), with a master whose waits
    serve the rig and move the clock one period."""
    clock = SimClock()
    channel = f"tsmd-rt-clock-{next(_CHANNELS)}"
    rig_bus = can.Bus(interface="virtual", channel=channel, receive_own_messages=False)
    master_bus = can.Bus(interface="virtual", channel=channel, receive_own_messages=False)
    configs = default_drive_configs()
    plant = TimedSpring()
    rig = SimRig(rig_bus, plant, configs, PERIOD_S, lockstep=False, clock=clock)

    def serve_then_wait_a_period() -> None:
        while (msg := rig_bus.recv(0)) is not None:
            rig.serve(msg)
        clock.advance(PERIOD_S)
        rig.serve(None)

    drives = CanOpenDrives(master_bus, configs, PERIOD_S, clock=clock,
                           idle=serve_then_wait_a_period, own_bus=True)
    yield rig, plant, clock, drives, serve_then_wait_a_period
    drives.close()
    rig.close()


def test_missing_syncs_do_not_stop_the_physics(fake_clock_rig):
    rig, plant, clock, _, _ = fake_clock_rig
    rig.serve(SYNC)
    start_s = plant.time_s
    missed = 20
    clock.advance(missed * PERIOD_S)
    rig.serve(SYNC)
    assert plant.time_s - start_s == pytest.approx(missed * PERIOD_S)
    assert rig.stalls == 0


def test_a_drive_keeps_moving_to_its_last_target_between_syncs(fake_clock_rig):
    rig, _, clock, drives, wait = fake_clock_rig
    drives.boot()
    drives.enable()
    drives.write_targets([20.0, 0.0])
    for _ in range(2):
        drives.sync()
        wait()
    per_sync_deg = rig.knob_deg()[0] / 2
    before_deg = rig.knob_deg()[0]
    clock.advance(10 * PERIOD_S)  # ten periods without a SYNC
    rig.serve(None)
    assert rig.knob_deg()[0] - before_deg > 5 * per_sync_deg
    assert rig.knob_deg()[0] < 20.0 + 0.01


def test_a_gap_longer_than_the_catch_up_bound_is_counted_as_a_stall(fake_clock_rig):
    rig, plant, clock, _, _ = fake_clock_rig
    rig.serve(SYNC)
    start_s = plant.time_s
    clock.advance(1.0)
    rig.serve(SYNC)
    steps_s = int(rig.max_catch_up_s / PERIOD_S) * PERIOD_S + PERIOD_S
    assert plant.time_s - start_s == pytest.approx(steps_s)
    assert rig.stalls == 1
    assert rig.stalled_s == pytest.approx(1.0 - steps_s)


def test_a_lockstep_rig_refuses_an_outside_clock():
    bus = can.Bus(interface="virtual", channel=f"tsmd-rt-clock-{next(_CHANNELS)}")
    with pytest.raises(ValueError, match="clock is for real time"):
        SimRig(bus, SpringPlant(), default_drive_configs(), PERIOD_S, clock=SimClock())
    bus.shutdown()
