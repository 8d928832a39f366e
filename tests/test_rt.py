"""The fixed-rate scheduler and the real-time set-up (behaviour, not speed)."""

from __future__ import annotations

import threading
import time

import numpy as np

from tsmd.rt import FixedRateScheduler, apply_realtime, set_normal_scheduling


def test_ticks_follow_absolute_deadlines_without_drift() -> None:
    period = 0.005
    scheduler = FixedRateScheduler(period, lambda: None)
    scheduler.run(threading.Event(), max_ticks=40)
    times = scheduler.times
    assert times.count == 40
    deadlines = times.starts() - times.lateness()
    if times.overruns == 0:  # a loaded machine may skip deadlines; the grid still holds
        assert np.allclose(np.diff(deadlines), period, atol=1e-9)
    steps = np.round(np.diff(deadlines) / period)
    assert np.allclose(np.diff(deadlines), steps * period, atol=1e-9)
    assert np.all(times.lateness() >= 0)


def test_a_tick_longer_than_the_period_is_an_overrun_and_its_deadlines_are_skipped() -> None:
    period = 0.005
    calls: list[float] = []
    overran: list[bool] = []

    def tick() -> None:
        calls.append(time.monotonic())
        if len(calls) == 3:
            time.sleep(3.5 * period)

    scheduler = FixedRateScheduler(period, tick, on_tick_end=overran.append)
    scheduler.run(threading.Event(), max_ticks=6)
    assert overran[2] is True
    assert scheduler.times.overruns >= 1
    assert scheduler.times.missed_deadlines >= 3
    # no burst of catch-up ticks after the long one
    assert calls[3] - calls[2] >= 3.5 * period


def test_a_reanchor_after_a_blocking_command_is_not_an_overrun() -> None:
    period = 0.005
    flag = {"n": 0}

    def tick() -> None:
        flag["n"] += 1
        if flag["n"] == 2:
            time.sleep(4 * period)

    overran: list[bool] = []
    scheduler = FixedRateScheduler(period, tick, on_tick_end=overran.append,
                                   should_reanchor=lambda: flag["n"] == 2)
    scheduler.run(threading.Event(), max_ticks=4)
    assert overran[1] is False  # the blocking tick itself
    starts = scheduler.times.starts()
    assert starts[2] - starts[1] >= 4 * period  # the next tick comes a period after, no burst


def test_realtime_settings_that_are_refused_become_warnings() -> None:
    def run() -> None:
        report = apply_realtime(priority=0, cpu=10_000, lock=False)
        results.append(report)

    results: list[object] = []
    thread = threading.Thread(target=run)
    thread.start()
    thread.join()
    (report,) = results
    assert report.cpu is None  # type: ignore[attr-defined]
    assert any("CPU 10000" in w for w in report.warnings)  # type: ignore[attr-defined]
    assert report.fifo_priority is None  # type: ignore[attr-defined]


def test_normal_scheduling_can_always_be_restored() -> None:
    results: list[object] = []
    thread = threading.Thread(target=lambda: results.append(set_normal_scheduling()))
    thread.start()
    thread.join()
    assert results == [None]
