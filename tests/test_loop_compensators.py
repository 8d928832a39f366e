"""Switching compensation on mid-run: the compensators standing by follow the motor
(tsmd.loop_compensators), so the one switched on starts on the branch the catheter is on."""

from __future__ import annotations

from collections.abc import Iterator
from concurrent.futures import Future
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.profiles import make_profile

from tsmd.compensation import NoCompensation
from tsmd.config import default_sim_config, resolve_data_path
from tsmd.loop import ControlLoop, Playback
from tsmd.profile import CatheterProfile, load_profile
from tsmd.service import CompensationChoice, Service
from tsmd.stack import build_loop, make_compensator, make_standby, open_sim

CONFIG = default_sim_config()
PERIOD_S = CONFIG.loop.period_s


def ramp(a_deg: float, b_deg: float, duration_s: float) -> list[float]:
    return list(np.linspace(a_deg, b_deg, round(duration_s / PERIOD_S)))


def enabled_sim_loop(compensator: Any, label: str, standby: Any = None
                     ) -> tuple[ControlLoop, Any]:
    """A lockstep loop on the sim rig (the packaged config's plant, seed 0), booted and
    enabled; the caller closes the rig."""
    drives, rig = open_sim(CONFIG, 0, lockstep=True)
    loop = build_loop(CONFIG, drives, compensator, rig.clock, compensation_label=label,
                      tip_source=rig.tip_pair, after_sync=rig.exchange, standby=standby)
    drives.boot()
    loop.tick()
    loop.execute("enable")
    return loop, rig


@pytest.fixture(scope="module")
def sim_profile() -> CatheterProfile:
    """The simulated catheter's own calibrated profile (what `tsmd run --sim` loads)."""
    return load_profile(resolve_data_path("profiles/example-sim.yaml"))


@pytest.fixture
def uncompensated_loop(sim_profile: CatheterProfile) -> Iterator[tuple[ControlLoop, object]]:
    """A lockstep loop on the simulated rig, compensation off, ours and paper standing by."""
    loop, rig = enabled_sim_loop(NoCompensation(), "none",
                                 make_standby(sim_profile, "ours", "none", CONFIG))
    yield loop, rig
    rig.close()


def play_phi1(loop: ControlLoop, path_deg: list[float]) -> None:
    for q in path_deg:
        loop.setpoint.set((q, 0.0))
        loop.tick()


def test_switching_on_at_a_standstill_after_moving_without_compensation_brings_the_tip_to_q(
        uncompensated_loop: tuple[ControlLoop, object], sim_profile: CatheterProfile) -> None:
    # 0 -> 60 -> 0 without compensation: the tip is left held high in the dead zone (~31 deg)
    loop, _rig = uncompensated_loop
    play_phi1(loop, ramp(0.0, 60.0, 2.0) + ramp(60.0, 0.0, 2.0) + [0.0] * 250)
    assert loop.latest_sample is not None and loop.latest_sample.tip_deg[0] > 20.0
    loop.execute("set_compensator", compensator=make_compensator(sim_profile, "ours", CONFIG),
                 label="ours", standby=make_standby(sim_profile, "ours", "ours", CONFIG),
                 keep_state=True)
    play_phi1(loop, [0.0] * 500)
    # a compensator started at rest believes the tip is at q and leaves it at ~31 deg
    assert abs(loop.latest_sample.tip_deg[0]) < 3.0


def test_the_compensator_switched_on_knows_the_catheter_came_down(
        uncompensated_loop: tuple[ControlLoop, object], sim_profile: CatheterProfile) -> None:
    loop, _rig = uncompensated_loop
    play_phi1(loop, ramp(0.0, 60.0, 2.0) + ramp(60.0, 20.0, 1.5))
    ours = make_compensator(sim_profile, "ours", CONFIG)
    loop.execute("set_compensator", compensator=ours, label="ours",
                 standby=make_standby(sim_profile, "ours", "ours", CONFIG), keep_state=True)
    state = ours._k[0].state  # type: ignore[attr-defined]
    assert state.direction == -1  # a rest start assumes the knob came up from home
    assert state.x_deg == pytest.approx(20.0, abs=0.5)  # where the motor is
    assert state.y_deg < 20.0 - 1.0  # the model's tip: down its falling branch, not at q


class PostedNow:
    """A lockstep loop whose posted commands run at once (no loop thread in these tests)."""

    def __init__(self, loop: ControlLoop) -> None:
        self._loop = loop

    def post(self, name: str, **args: Any) -> Future[Any]:
        future: Future[Any] = Future()
        future.set_result(self._loop.execute(name, **args))
        return future

    def __getattr__(self, name: str) -> Any:
        return getattr(self._loop, name)


def test_the_api_switching_compensation_off_and_on_keeps_the_branch(
        sim_profile: CatheterProfile, tmp_path: Path) -> None:
    # what the README demo does: compensation off, knobs moved, compensation on
    loop, rig = enabled_sim_loop(make_compensator(sim_profile, "ours", CONFIG), "ours")
    service = Service(CONFIG, PostedNow(loop), sim_profile,  # type: ignore[arg-type]
                      CompensationChoice(True, "ours"), profiles_dir=tmp_path)
    try:
        service.set_compensation(False, None)
        play_phi1(loop, ramp(0.0, 60.0, 2.0) + ramp(60.0, 0.0, 2.0) + [0.0] * 250)
        service.set_compensation(True, None)
        play_phi1(loop, [0.0] * 500)
    finally:
        rig.close()
    assert loop.latest_sample is not None and abs(loop.latest_sample.tip_deg[0]) < 3.0


def test_switching_with_a_new_profile_starts_at_rest(
        uncompensated_loop: tuple[ControlLoop, object], sim_profile: CatheterProfile) -> None:
    loop, _rig = uncompensated_loop
    play_phi1(loop, ramp(0.0, 60.0, 2.0) + ramp(60.0, 20.0, 1.5))
    ours = make_compensator(sim_profile, "ours", CONFIG)
    loop.execute("set_compensator", compensator=ours, label="ours", keep_state=False)
    state = ours._k[0].state  # type: ignore[attr-defined]
    assert (state.direction, state.y_deg) == (1, pytest.approx(20.0, abs=0.1))


def test_ours_after_following_the_motor_starts_where_the_motor_is() -> None:
    profile = make_profile()
    followed = make_compensator(profile, "ours", CONFIG)
    fresh = make_compensator(profile, "ours", CONFIG)
    motor = 0.0
    for q in ramp(0.0, 50.0, 1.0):
        motor = q
        followed.follow(np.array([q, 0.0]), np.array([motor, 0.0]), PERIOD_S)  # type: ignore[attr-defined]
    fresh.reset(np.array([50.0, 0.0]))
    v_max = CONFIG.limits.phi1.max_velocity_deg_s
    first = followed.command(np.array([50.0, 0.0]), PERIOD_S)[0]
    assert abs(first - motor) <= v_max * PERIOD_S + 1e-9
    assert abs(fresh.command(np.array([50.0, 0.0]), PERIOD_S)[0] - motor) > v_max * PERIOD_S


def test_paper_follows_the_motor_down_its_falling_branch() -> None:
    paper = make_compensator(make_profile(), "paper", CONFIG)
    for x in ramp(0.0, 60.0, 1.0) + ramp(60.0, 10.0, 1.0):
        paper.follow(np.array([x, 0.0]), np.array([x, 0.0]), PERIOD_S)  # type: ignore[attr-defined]
    state = paper.states[0]  # type: ignore[attr-defined]
    assert (state.direction, state.x_deg) == (-1, pytest.approx(10.0))


def demo_sine_rmse_after_load(late_every: int) -> tuple[float, float]:
    """Ours on the demo's sine (a 50 Hz client on wall time) for 30 s; in the first 15 s every
    ``late_every``-th tick comes late by two periods (the client's sine moves on, the rig and the
    compensator advance one tick). Tip RMSE per knob over the last 10 s."""
    profile = load_profile(resolve_data_path("profiles/example-sim.yaml"))
    loop, rig = enabled_sim_loop(make_compensator(profile, "ours", CONFIG), "ours")
    wall_s, k, errors = 0.0, 0, []
    while wall_s < 30.0:
        t_s = np.floor(wall_s * 50.0) / 50.0
        loop.setpoint.set((60.0 * np.sin(2 * np.pi * 0.1 * t_s),
                           30.0 * np.sin(4 * np.pi * 0.1 * t_s)))
        sample = loop.tick()
        if wall_s >= 20.0:
            errors.append(np.subtract(sample.tip_deg, sample.q_deg))
        k += 1
        late = late_every > 0 and wall_s < 15.0 and k % late_every == 0
        loop.note_overrun(late)
        wall_s += PERIOD_S * (3 if late else 1)
    rig.close()
    rmse = np.sqrt(np.mean(np.square(errors), axis=0))
    return float(rmse[0]), float(rmse[1])


def test_late_ticks_leave_no_lasting_error_once_the_load_is_gone() -> None:
    calm = demo_sine_rmse_after_load(0)
    loaded = demo_sine_rmse_after_load(7)
    assert loaded == pytest.approx(calm, abs=0.15)


def test_nothing_moves_after_an_uncompensated_trajectory_ends(
        sim_profile: CatheterProfile) -> None:
    # a calibration sweep ends held at its last knob angle, which is not where the tip is
    loop, rig = enabled_sim_loop(make_compensator(sim_profile, "ours", CONFIG), "ours")
    path = np.column_stack([ramp(0.0, 60.0, 2.0) + ramp(60.0, 0.0, 2.0), np.zeros(1000)])
    playback = Playback(path, False, None)
    loop.execute("play", playback=playback)
    try:
        while not playback.done.is_set():
            loop.tick()
        commands = [loop.tick().cmd_deg[0] for _ in range(250)]
    finally:
        rig.close()
    assert max(abs(c) for c in commands) < 0.5
