"""`tsmd bench compute`: the compensator's cost per tick under the normal scheduler and as the
daemon's loop runs it (behaviour, not speed)."""

from __future__ import annotations

import gc
import os
from contextlib import nullcontext

import pytest

from tsmd import cli
from tsmd.bench import compute
from tsmd.config import resolve_data_path
from tsmd.rt import fifo_scheduling

EXAMPLE = str(resolve_data_path("profiles/example-sim.yaml"))


def _scheduler() -> int:
    return os.sched_getscheduler(0)


def test_fifo_scheduling_ends_with_the_normal_scheduler() -> None:
    with fifo_scheduling(10) as refused:
        inside = _scheduler()
    if refused is not None:
        pytest.skip(f"SCHED_FIFO not allowed here: {refused}")
    assert inside == os.SCHED_FIFO
    assert _scheduler() == os.SCHED_OTHER


def test_a_refused_fifo_is_reported_and_changes_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*_: object) -> None:
        raise PermissionError(1, "Operation not permitted")

    monkeypatch.setattr(os, "sched_setscheduler", refuse)
    with fifo_scheduling(10) as refused:
        assert refused is not None and "not permitted" in refused


def test_the_bench_times_each_profile_both_ways_and_unfreezes_the_collector(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    frozen: list[int] = []
    monkeypatch.setattr(compute, "compute_time_us",
                        lambda *a, **k: frozen.append(gc.get_freeze_count()) or (1.0, 2.0))
    monkeypatch.setattr(compute, "fifo_scheduling", lambda priority: nullcontext())
    assert cli.main(["bench", "compute", EXAMPLE, "--ticks", "100"]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if "example-sim" in line]
    assert [r.split("|")[2].strip()[:6] for r in rows] == ["normal", "as the"]
    assert len(frozen) == 6 and min(frozen[3:]) > max(frozen[:3])
    assert gc.get_freeze_count() == 0


def test_a_priority_outside_the_fifo_range_is_one_clear_error(
        capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["bench", "compute", EXAMPLE, "--fifo-priority", "0"]) != 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--fifo-priority 0" in err[0]

