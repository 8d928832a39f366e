"""The loop's observer hook: every tick's row reaches the online worker, updates come back."""

from __future__ import annotations

from pathlib import Path

import pytest
from support.drives import FakeDrives

from drivers.clock import SimClock
from tsmd.compensation import build_compensator
from tsmd.compensation.safety import KnobLimiter, KnobLimits
from tsmd.loop import ROW_COLUMNS, ControlLoop, MemoryRecorder
from tsmd.online import OnlineWorker, shifted_knob
from tsmd.profile import load_profile

PERIOD_S = 0.004
PROFILE = Path(__file__).resolve().parents[1] / "profiles" / "example-sim.yaml"


def make_loop() -> tuple[ControlLoop, FakeDrives, OnlineWorker]:
    comp = build_compensator(load_profile(PROFILE), "ours", PERIOD_S)
    drives = FakeDrives()
    clock = SimClock()
    loop = ControlLoop(drives, comp, KnobLimiter([KnobLimits(-90.0, 90.0, 120.0, 2000.0)] * 2,
                                                 PERIOD_S),
                       PERIOD_S, clock,
                       after_sync=lambda: clock.advance(PERIOD_S), recorder=MemoryRecorder())
    worker = OnlineWorker(comp, PERIOD_S, ROW_COLUMNS)
    loop.observer = worker.observe
    return loop, drives, worker


def test_every_tick_hands_its_row_and_state_to_the_observer() -> None:
    loop, _, worker = make_loop()
    loop.tick()
    loop.execute("enable")
    loop.tick()
    assert [enabled for _, enabled in worker.queue] == [False, True]
    assert worker.queue[-1][0][0] == loop.latest_sample.t_s  # type: ignore[union-attr]


def final_command(shift_deg: float) -> float:
    """phi1's command after a slow rise to 50 deg, with D_pos moved out by ``shift_deg``."""
    loop, _, worker = make_loop()
    loop.tick()
    loop.execute("enable")
    offsets = ((shift_deg, 0.0), (0.0, 0.0))
    worker.published = (1, offsets, (shifted_knob(worker.base_knobs[0], offsets[0]),
                                     worker.base_knobs[1]))
    for i in range(1000):
        loop.setpoint.set((30.0 + 20.0 * i / 999, 0.0))
        loop.tick()
    for _ in range(100):
        loop.tick()
    return float(loop.latest_sample.cmd_deg[0])  # type: ignore[union-attr]


def test_a_published_shift_moves_the_loaded_command_by_as_much() -> None:
    assert final_command(3.0) - final_command(0.0) == pytest.approx(3.0, abs=0.05)
