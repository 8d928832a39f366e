"""Our master boots two simulated drives and streams a CSP trajectory they follow (lockstep)."""

from __future__ import annotations

import numpy as np
import pytest
from support.plants import PairPlant, SpringPlant

from drivers.drive import DriveState
from drivers.units import DriveConfig
from simrig.plant import PlantOutputError, as_plant_step
from simrig.plants.capstan.tendon_sheath import TendonSheathPlant
from simrig.rig import IdealCurrentSensor, open_sim_rig

PERIOD_S = 0.004


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
    seen: list[int] = []
    send, recv = drives.bus.send, drives.bus.recv

    def tapped_send(msg, timeout=None):
        seen.append(msg.arbitration_id)
        send(msg, timeout)

    def tapped_recv(timeout=None):
        msg = recv(timeout)
        if msg is not None:
            seen.append(msg.arbitration_id)
        return msg

    drives.bus.send, drives.bus.recv = tapped_send, tapped_recv
    q = sine(250)
    heartbeats = 0
    for k in range(len(q)):
        seen.clear()
        run(drives, rig, q[k:k + 1])
        cyclic = [cid for cid in seen if not 0x700 <= cid <= 0x77F]
        heartbeats += len(seen) - len(cyclic)
        assert sorted(cyclic) == [0x080, 0x181, 0x182, 0x201, 0x202]
    # master and both drives beat every 50 ms: 3 frames per 12.5 ticks
    assert 50 <= heartbeats <= 70


def test_replay_depends_on_the_seed_only_through_the_sensor_noise():
    def currents(seed: int) -> list[float]:
        drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S, seed=seed)
        try:
            drives.boot()
            drives.enable()
            out = []
            for q in sine(200):
                run(drives, rig, q[None, :])
                out.append(drives.feedback()[0].current_A)
            return out
        finally:
            drives.close()
            rig.close()

    assert currents(1) == currents(1)
    assert currents(1) != currents(2)


def test_default_plant_is_the_tendon_sheath_physics():
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


def test_boot_writes_mode_period_limits_and_heartbeats_to_the_drive(rig_pair):
    drives, _ = rig_pair
    drives.boot()
    cfg = DriveConfig(node_id=1)
    cpd = cfg.counts_per_deg
    expected = {
        (0x6060, 0): 8,
        (0x60C2, 1): 4, (0x60C2, 2): -3,
        (0x1006, 0): 4000,
        (0x607D, 1): round(cfg.min_deg * cpd), (0x607D, 2): round(cfg.max_deg * cpd),
        (0x607F, 0): round(cfg.max_velocity_deg_s * cpd),
        (0x6080, 0): round(cfg.max_velocity_deg_s * cfg.gear_ratio / 6.0 * 1.25),
        (0x6085, 0): round(cfg.max_accel_deg_s2 * cpd),
        (0x6065, 0): round(cfg.following_error_deg * cpd),
        (0x605A, 0): cfg.quick_stop_option,
        (0x6007, 0): cfg.abort_connection_option,
        (0x1017, 0): cfg.heartbeat_producer_ms,
        (0x1016, 1): (127 << 16) | cfg.master_heartbeat_timeout_ms,
        (0x1600, 0): 2, (0x1600, 1): 0x60400010, (0x1600, 2): 0x607A0020,
        (0x1A00, 0): 3, (0x1A00, 1): 0x60410010, (0x1A00, 2): 0x60640020,
        (0x1A00, 3): 0x60780010,
        (0x1800, 1): 0x181, (0x1800, 2): 1, (0x1400, 1): 0x201, (0x1400, 2): 1,
    }
    got = {key: drives.sdo_read(0, *key) for key in expected}
    assert got == expected


def test_segmented_sdo_upload_reads_the_device_name(rig_pair):
    drives, _ = rig_pair
    drives.boot()
    assert drives.sdo_read(1, 0x1008) == "tsmd simulated knob drive"


def test_feedback_is_in_knob_degrees_and_amperes_within_one_raw_unit():
    drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S, seed=0,
                               rig_kwargs={"sensors": [IdealCurrentSensor(),
                                                       IdealCurrentSensor()]})
    try:
        drives.boot()
        drives.enable()
        run(drives, rig, np.linspace([0.0, 0.0], [45.0, -20.0], 300))
        cfg = DriveConfig(node_id=1)
        for fb, motor in zip(drives.feedback(), rig.motors, strict=True):
            assert abs(fb.position_deg - motor.position_deg) <= 0.5 / cfg.counts_per_deg
            assert abs(fb.current_A - motor.current_A) <= 0.5 * cfg.current_scale_A + 1e-12
    finally:
        drives.close()
        rig.close()


def test_a_plant_answering_a_plain_pair_drives_the_rig_like_its_plantstep_twin() -> None:
    q = sine(300)
    results = []
    for plant in (SpringPlant(), PairPlant()):
        drives, rig = open_sim_rig(plant, None, PERIOD_S, seed=3)
        try:
            drives.boot()
            drives.enable()
            pos = run(drives, rig, q)
            results.append((pos, rig.tip_deg(), [f.current_A for f in drives.feedback()]))
        finally:
            drives.close()
            rig.close()
    (pos_a, tip_a, cur_a), (pos_b, tip_b, cur_b) = results
    assert np.array_equal(pos_a, pos_b)
    assert np.array_equal(tip_a, tip_b) and cur_a == cur_b


@pytest.mark.parametrize("answer", [None, (1.0, 2.0), ([1.0, 2.0, 3.0], [0.0, 0.0]), "ab"])
def test_a_plant_answer_that_is_neither_plantstep_nor_pair_is_named(answer: object) -> None:
    with pytest.raises(PlantOutputError, match="PlantStep or a pair"):
        as_plant_step(answer)  # type: ignore[arg-type]


def test_feedback_ages_with_each_sync_and_is_fresh_again_after_the_answer(rig_pair):
    drives, rig = rig_pair
    drives.boot()
    drives.enable()
    before = drives.feedback()
    drives.sync()
    aged = drives.feedback()
    rig.exchange()
    drives.pump()
    answered = drives.feedback()
    assert [f.age_syncs for f in before] == [0, 0]
    assert [f.age_syncs for f in aged] == [1, 1]
    assert [f.age_syncs for f in answered] == [0, 0]


def test_feedback_follows_a_changed_position_between_two_reads(rig_pair):
    drives, rig = rig_pair
    drives.boot()
    drives.enable()
    first = drives.feedback()
    run(drives, rig, np.tile([10.0, -5.0], (100, 1)))
    moved = drives.feedback()
    assert moved[0].position_deg == pytest.approx(10.0, abs=0.5)
    assert moved[1].position_deg == pytest.approx(-5.0, abs=0.5)
    assert first[0].position_deg == pytest.approx(0.0, abs=0.1)


def test_tip_pair_gives_the_tip_deg_values_of_a_twin_rig() -> None:
    runs = []
    for use_pair in (False, True):
        drives, rig = open_sim_rig(SpringPlant(), None, PERIOD_S, seed=5)
        drives.boot()
        drives.enable()
        tips = []
        for q in sine(50):
            drives.write_targets(q)
            drives.sync()
            rig.exchange()
            drives.pump()
            tips.append(list(rig.tip_pair()) if use_pair else rig.tip_deg().tolist())
        runs.append(tips)
        drives.close()
        rig.close()
    assert runs[0] == runs[1]
