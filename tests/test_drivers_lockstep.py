"""Our master boots two simulated drives and streams a CSP trajectory they follow (lockstep)."""

from __future__ import annotations

import numpy as np
import pytest

from drivers.drive import DriveState
from drivers.plant.base import PlantStep
from drivers.sim.rig import open_sim_rig
from drivers.units import DriveConfig

PERIOD_S = 0.004


class SpringPlant:
    """Stand-in catheter: a linear torsion spring per knob, tip = 1.3 x knob."""

    def __init__(self, stiffness_Nm_deg: float = 0.002) -> None:
        self.stiffness = stiffness_Nm_deg

    def reset(self) -> None:
        pass

    def step(self, dt_s: float, knob_deg: np.ndarray) -> PlantStep:
        return PlantStep(tip_deg=1.3 * knob_deg, knob_torque_Nm=self.stiffness * knob_deg)


@pytest.fixture()
def rig_pair():
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S, seed=3)
    yield drives, rig
    drives.close()
    rig.close()


def run(drives, rig, q_deg: np.ndarray) -> np.ndarray:
    pos = np.empty_like(q_deg)
    for k, q in enumerate(q_deg):
        drives.write_targets(q)
        drives.sync()
        rig.exchange()
        drives.pump()
        pos[k] = [f.position_deg for f in drives.feedback()]
    return pos


def sine(n: int, amp_deg: float = 40.0, freq_hz: float = 0.5) -> np.ndarray:
    t = np.arange(n) * PERIOD_S
    q = amp_deg * np.sin(2 * np.pi * freq_hz * t)
    return np.stack([q, -0.5 * q], axis=1)


def test_boot_then_enable_reaches_operation_enabled(rig_pair):
    drives, _rig = rig_pair
    drives.boot()
    drives.enable()
    assert [f.state for f in drives.feedback()] == [DriveState.OPERATION_ENABLED] * 2
    assert drives.poll_events() == []


def test_drives_follow_a_csp_trajectory(rig_pair):
    drives, rig = rig_pair
    drives.boot()
    drives.enable()
    q = sine(1000)
    pos = run(drives, rig, q)
    # feedback answers the SYNC of the same tick: tracking error only from the drive's bandwidth
    assert np.max(np.abs(pos[50:] - q[50:])) < 1.0
    assert np.allclose(rig.knob_deg(), pos[-1], atol=1e-3)
    assert drives.poll_events() == []


def test_feedback_current_follows_the_spring_load(rig_pair):
    drives, rig = rig_pair
    drives.boot()
    drives.enable()
    hold = np.tile([60.0, -30.0], (400, 1))
    run(drives, rig, np.linspace([0.0, 0.0], [60.0, -30.0], 400))
    run(drives, rig, hold)
    cur = [f.current_A for f in drives.feedback()]
    assert cur[0] > 0 > cur[1]
    assert abs(cur[0]) > 1.5 * abs(cur[1])


def test_lockstep_replay_is_bit_for_bit_repeatable():
    results = []
    for _ in range(2):
        drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S, seed=11)
        drives.boot()
        drives.enable()
        results.append(run(drives, rig, sine(300)))
        drives.close()
        rig.close()
    assert np.array_equal(results[0], results[1])


def test_targets_outside_the_limits_are_clamped_before_sending(rig_pair):
    drives, rig = rig_pair
    drives.boot()
    drives.enable()
    ramp = np.linspace([0.0, 0.0], [200.0, -200.0], 2000)
    pos = run(drives, rig, ramp)
    limit = DriveConfig(node_id=1).max_deg
    assert np.allclose(np.abs(pos[-1]), limit, atol=1e-3)  # settled on the clamped target
    assert np.max(np.abs(pos)) <= limit + 0.1  # only the drive's own overshoot on arrival


def test_at_most_five_cyclic_frames_per_tick(rig_pair):
    drives, rig = rig_pair
    drives.boot()
    drives.enable()
    sent0, recv0 = drives.frames_sent, drives.frames_received
    ticks = 250
    run(drives, rig, sine(ticks))
    sent = drives.frames_sent - sent0
    received = drives.frames_received - recv0
    # heartbeats (master 50 ms, drives 50 ms) come on top of the 5 cyclic frames
    heartbeats = 3 * ticks * PERIOD_S / 0.05
    assert sent + received <= 5 * ticks + heartbeats + 3
    assert received >= 2 * ticks


def test_default_plant_is_the_tendon_sheath_physics():
    from drivers.plant.tendon_sheath import TendonSheathPlant

    drives, rig = open_sim_rig(None, None, PERIOD_S, seed=0)
    try:
        assert isinstance(rig.plant, TendonSheathPlant)
        drives.boot()
        drives.enable()
        run(drives, rig, np.linspace([0.0, 0.0], [70.0, 0.0], 500))
        # pulling a tendon past the dead zone loads the motor; the idle knob stays near zero
        cur = [f.current_A for f in drives.feedback()]
        assert abs(cur[0]) > 0.02
        assert abs(rig.true_tip_deg()[0]) > 5.0
    finally:
        drives.close()
        rig.close()
