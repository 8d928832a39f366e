"""The worker beside the loop: strokes in, offsets published, compensator updated between ticks."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.online import profile_edges, rows

from tsmd.compensation import build_compensator
from tsmd.loop import ROW_COLUMNS
from tsmd.online import (
    OnlineError,
    OnlineWorker,
    profile_with_offsets,
    save_online_version,
    shifted_knob,
)
from tsmd.online.apply import edges_at
from tsmd.profile import load_profile

PROFILE = Path(__file__).resolve().parents[1] / "profiles" / "example-sim.yaml"


@pytest.fixture(scope="module")
def profile() -> Any:
    return load_profile(PROFILE)


def make_worker(profile: Any) -> tuple[OnlineWorker, Any, tuple[Any, Any]]:
    """A worker on a fresh compensator, and the compensator's original knobs (the truth)."""
    comp = build_compensator(profile, "ours", 0.004)
    return OnlineWorker(comp, 0.004, ROW_COLUMNS, drain_every=25), comp, comp.knobs


def feed(worker: OnlineWorker, data: list[tuple[float, ...]], enabled: bool = True) -> None:
    for row in data:
        worker.observe(row, enabled)
    worker.drain()
    worker.observe(data[-1], enabled)  # the loop's next tick picks the last update up



def largest_command_difference_deg(live: Any, saved: Any) -> float:
    """Both compensators driven through 30 s of two-knob motion from the same start."""
    t = np.arange(0.0, 30.0, 0.004)
    q = np.column_stack([50 * np.sin(2 * np.pi * 0.07 * t), 40 * np.sin(2 * np.pi * 0.05 * t)])
    live.reset(q[0])
    saved.reset(q[0])
    return max(float(np.max(np.abs(live.command(row, 0.004) - saved.command(row, 0.004))))
               for row in q)

def test_step_change_is_recovered_and_reaches_the_compensator(profile: Any) -> None:
    worker, comp, base = make_worker(profile)
    feed(worker, rows(200.0, profile_edges(base, 4.0, at_s=100.0)))
    for knob in (0, 1):
        for side in (0, 1):
            assert worker.offsets()[knob][side] == pytest.approx(4.0, abs=0.8)
    d_pos, d_neg = edges_at(comp.knobs[0], 0.0)
    b_pos, b_neg = edges_at(base[0], 0.0)
    assert d_pos == pytest.approx(b_pos + worker.offsets()[0][0], abs=1e-9)
    assert d_neg == pytest.approx(b_neg - worker.offsets()[0][1], abs=1e-9)


def test_no_change_no_drift(profile: Any) -> None:
    worker, _, base = make_worker(profile)
    feed(worker, rows(300.0, profile_edges(base), seed=1))
    assert max(abs(v) for pair in worker.offsets() for v in pair) <= 0.5


def test_spikes_do_not_move_the_offsets(profile: Any) -> None:
    worker, _, base = make_worker(profile)
    feed(worker, rows(200.0, profile_edges(base), spike_rate=0.01,
                      seed=2))
    assert max(abs(v) for pair in worker.offsets() for v in pair) <= 0.5


def test_twice_the_noise_keeps_the_offsets_within_a_degree(profile: Any) -> None:
    worker, _, base = make_worker(profile)
    feed(worker, rows(200.0, profile_edges(base), noise_A=0.006,
                      spike_rate=0.01, seed=4))
    assert max(abs(v) for pair in worker.offsets() for v in pair) <= 1.0


def test_a_stalled_motor_freezes_the_estimate(profile: Any) -> None:
    worker, _, base = make_worker(profile)
    # phi1 stalls over a whole stroke out of the dead zone while its edges "move"
    data = rows(120.0, profile_edges(base), seed=3)
    stalled = rows(40.0, profile_edges(base, 5.0), stall=(0, 0.0, 40.0),
                   seed=4)
    feed(worker, data)
    t0 = data[-1][0] + 0.004
    feed(worker, [(r[0] + t0, *r[1:]) for r in stalled])
    assert worker.offsets()[0] == (0.0, 0.0)
    assert any(e["event"] == "online estimate frozen" for e in worker.events)


def test_a_fault_freezes_the_estimate(profile: Any) -> None:
    worker, _, base = make_worker(profile)
    data = rows(200.0, profile_edges(base, 4.0, at_s=100.0), seed=5)
    feed(worker, data[:25000])  # until t = 100 s: the change has not happened yet
    feed(worker, data[25000:], enabled=False)  # loop in FAULT: rows come, nothing is learned
    assert worker.offsets() == ((0.0, 0.0), (0.0, 0.0))
    assert worker.status()["edges"]["phi1_pos"]["state"] == "frozen"


def warnings(worker: OnlineWorker) -> list[str]:
    return [e["event"] for e in worker.events if e["level"] == "warning"]


def test_a_loop_disabled_at_start_does_not_warn(profile: Any) -> None:
    worker, _, base = make_worker(profile)
    data = rows(60.0, profile_edges(base), seed=7)
    feed(worker, data[:2500], enabled=False)  # the daemon starts with the drives disabled
    feed(worker, data[2500:])
    assert warnings(worker) == []
    assert worker.status()["edges"]["phi1_pos"]["frozen_reason"] is None


def test_a_stop_while_enabled_freezes_without_a_warning(profile: Any) -> None:
    worker, _, base = make_worker(profile)
    data = rows(60.0, profile_edges(base), seed=8)
    feed(worker, data[:10000])
    feed(worker, data[10000:], enabled=False)
    assert warnings(worker) == []
    edge = worker.status()["edges"]["phi1_pos"]
    assert edge["frozen_reason"] == "the loop was stopped or disabled"


def test_a_fault_while_enabled_freezes_with_a_warning_naming_it(profile: Any) -> None:
    comp = build_compensator(profile, "ours", 0.004)
    fault: list[str | None] = [None]
    worker = OnlineWorker(comp, 0.004, ROW_COLUMNS, drain_every=25,
                          fault_reason=lambda: fault[0])
    data = rows(60.0, profile_edges(comp.knobs), seed=9)
    feed(worker, data[:10000])
    fault[0] = "drive 0: heartbeat lost"
    feed(worker, data[10000:], enabled=False)
    frozen = [e for e in worker.events if e["event"] == "online estimate frozen"]
    assert len(frozen) == 1 and frozen[0]["level"] == "warning"
    assert "heartbeat lost" in frozen[0]["reason"]


def test_the_data_sheets_handle_slip_is_used_per_knob(profile: Any) -> None:
    comp = build_compensator(profile, "ours", 0.004)
    worker = OnlineWorker(comp, 0.004, ROW_COLUMNS, handle_slip_deg=(1.5, 4.0))
    assert [o.handle_slip_deg for o in worker._knob_ramp] == [1.5, 4.0]


@pytest.mark.parametrize("slip", [(0.0, 3.0), (3.0, float("nan"))])
def test_a_bad_handle_slip_is_refused_in_one_line(profile: Any,
                                                  slip: tuple[float, float]) -> None:
    comp = build_compensator(profile, "ours", 0.004)
    with pytest.raises(OnlineError, match="handle_slip_deg must be > 0"):
        OnlineWorker(comp, 0.004, ROW_COLUMNS, handle_slip_deg=slip)


def test_switching_off_restores_the_profiles_values(profile: Any) -> None:
    worker, comp, base = make_worker(profile)
    original = comp.knobs
    feed(worker, rows(200.0, profile_edges(base, 4.0, at_s=100.0), seed=6))
    assert comp.knobs[0] is not original[0]
    worker.set_enabled(False)
    worker.observe(worker_row(), True)
    assert all(a is b for a, b in zip(comp.knobs, original, strict=True))
    assert worker.status()["offsets_deg"] == [[0.0, 0.0], [0.0, 0.0]]


def worker_row() -> tuple[float, ...]:
    return tuple(0.0 if c != "t" else 1e6 for c in ROW_COLUMNS)


def test_an_update_reaches_the_compensator_only_at_a_tick(profile: Any) -> None:
    worker, comp, _ = make_worker(profile)
    knobs_before = comp.knobs
    version, offsets, knobs = worker.published
    worker.published = (version + 1, offsets, (knobs[1], knobs[0]))
    assert comp.knobs is knobs_before  # published, not yet picked up
    worker.observe(worker_row(), True)
    assert comp.knobs[0] is knobs[1]


def test_the_queue_is_bounded(profile: Any) -> None:
    comp = build_compensator(profile, "ours", 0.004)
    worker = OnlineWorker(comp, 0.004, ROW_COLUMNS, queue_len=100)
    for _ in range(1000):
        worker.observe(worker_row(), True)
    assert len(worker.queue) == 100


def test_saving_writes_a_new_version_and_keeps_the_calibrated_file(profile: Any,
                                                                   tmp_path: Path) -> None:
    calibrated = tmp_path / f"{profile.catheter_id}.yaml"
    calibrated.write_bytes(PROFILE.read_bytes())
    offsets = ((3.0, 2.0), (1.0, -1.0))
    first = save_online_version(profile, offsets, tmp_path)
    second = save_online_version(profile, offsets, tmp_path)
    assert first != second and calibrated.read_bytes() == PROFILE.read_bytes()
    saved = load_profile(first)
    k = saved.knobs[0]
    assert np.allclose(k.dead_zone_pos_deg, np.add(profile.knobs[0].dead_zone_pos_deg, 3.0))
    assert np.allclose(k.dead_zone_neg_deg, np.subtract(profile.knobs[0].dead_zone_neg_deg, 2.0))
    assert saved.quality["phi1_online_offset_pos_deg"] == 3.0


def test_a_saved_version_compensates_like_the_online_offsets(profile: Any) -> None:
    offsets = ((3.0, 2.0), (1.0, -1.0))
    live = build_compensator(profile, "ours", 0.004)
    worker = OnlineWorker(live, 0.004, ROW_COLUMNS)
    worker.published = (1, offsets, (shifted_knob(worker.base_knobs[0], offsets[0]),
                                     shifted_knob(worker.base_knobs[1], offsets[1])))
    worker.observe(worker_row(), True)
    saved = build_compensator(profile_with_offsets(profile, offsets), "ours", 0.004)
    assert largest_command_difference_deg(live, saved) < 1e-6


def test_a_compensator_without_edges_is_refused_in_one_line(profile: Any) -> None:
    with pytest.raises(OnlineError, match="needs the 'ours' or 'paper' compensator"):
        OnlineWorker(build_compensator(None, "none", 0.004), 0.004, ROW_COLUMNS)


def test_the_paper_compensator_under_the_limiter_is_shifted_too(profile: Any) -> None:
    from tsmd.compensation import KnobLimits

    limited = build_compensator(profile, "paper", 0.004,
                                [KnobLimits(-90.0, 90.0, 120.0, 2000.0)] * 2)
    worker = OnlineWorker(limited, 0.004, ROW_COLUMNS)
    worker.published = (1, ((2.0, 0.0), (0.0, 0.0)), (
        shifted_knob(worker.base_knobs[0], (2.0, 0.0)), worker.base_knobs[1]))
    worker.observe(worker_row(), True)
    assert edges_at(limited.inner.knobs[0], 0.0)[0] == pytest.approx(  # type: ignore[attr-defined]
        edges_at(worker.base_knobs[0], 0.0)[0] + 2.0)


def test_a_sheath_bend_is_recovered(profile: Any) -> None:
    worker, _, base = make_worker(profile)
    # at 80 s every edge moves 4 deg out and both tendons' ramps become 3.5 x steeper
    feed(worker, rows(220.0, profile_edges(base, 4.0, at_s=80.0), friction=(80.0, 3.5),
                      seed=6))
    for knob in (0, 1):
        for side in (0, 1):
            assert worker.offsets()[knob][side] == pytest.approx(4.0, abs=1.0)


def test_a_stalled_motor_after_a_sheath_bend_still_freezes(profile: Any) -> None:
    worker, _, base = make_worker(profile)
    data = rows(220.0, profile_edges(base, 4.0, at_s=80.0), friction=(80.0, 3.5), seed=7)
    feed(worker, data)
    before = worker.offsets()[0]
    assert before == pytest.approx((4.0, 4.0), abs=1.0)  # the bend was followed
    stalled = rows(40.0, profile_edges(base, 9.0), friction=(0.0, 3.5), stall=(0, 0.0, 40.0),
                   seed=8)
    t0 = data[-1][0] + 0.004
    feed(worker, [(r[0] + t0, *r[1:]) for r in stalled])
    assert worker.offsets()[0] == before
    assert worker.events[-1]["event"] != "online shape change followed"
    assert any(e["event"] == "online estimate frozen" and e["t"] > t0 for e in worker.events)


def test_an_edge_coupling_the_profile_does_not_hold_moves_no_offset_beyond_it(
        profile: Any) -> None:
    """The coupling's share common to the other knob's range may show in the offsets (the
    bins are anchored to their visit-weighted mean, the reference is the baseline ramps'),
    but a walk would carry them beyond the coupling itself."""
    worker, _, base = make_worker(profile)
    coupling_deg = 0.8  # the current's edges sit further out with the other knob below -20 deg
    feed(worker, rows(600.0, profile_edges(base, other_below=(-20.0, coupling_deg)), seed=9))
    assert max(abs(v) for pair in worker.offsets() for v in pair) < coupling_deg


def test_a_sheath_bend_raises_the_backlash_gain_as_the_current_slope(profile: Any) -> None:
    worker, comp, base = make_worker(profile)
    feed(worker, rows(220.0, profile_edges(base, 4.0, at_s=80.0), friction=(80.0, 1.6),
                      seed=10))
    f0, f1 = base[0].field, comp.knobs[0].field
    beta = f0.column("backlash_gain_pos")
    assert f1.at(0.0)[beta] == pytest.approx(1.6 * f0.at(0.0)[beta], rel=0.1)
    assert comp.knobs[0].omega < base[0].omega  # the release slope omega / (1 - beta) stays


def test_without_a_change_the_backlash_gain_stays(profile: Any) -> None:
    worker, comp, base = make_worker(profile)
    feed(worker, rows(300.0, profile_edges(base), noise_A=0.006, seed=11))
    assert worker.gains == ((1.0, 1.0), (1.0, 1.0))
    assert comp.knobs[0].omega == base[0].omega


def test_a_saved_version_compensates_like_the_online_backlash_gains(profile: Any) -> None:
    offsets, gains = ((3.0, 2.0), (1.0, -1.0)), ((1.3, 1.2), (1.0, 1.5))
    live = build_compensator(profile, "ours", 0.004)
    worker = OnlineWorker(live, 0.004, ROW_COLUMNS)
    worker.published = (1, offsets, (shifted_knob(worker.base_knobs[0], offsets[0], gains[0]),
                                     shifted_knob(worker.base_knobs[1], offsets[1], gains[1])))
    worker.observe(worker_row(), True)
    saved = build_compensator(profile_with_offsets(profile, offsets, gains=gains), "ours",
                              0.004)
    assert largest_command_difference_deg(live, saved) < 1e-6


def test_a_knob_shifted_with_its_zero_load_points_kept_moves_only_the_edges(profile: Any) -> None:
    knob = build_compensator(profile, "ours", 0.004).knobs[0]
    f = knob.field
    moved = shifted_knob(knob, (3.0, 2.0), zero_load=(0.0, 0.0)).field
    for name, move in (("dead_zone_pos_deg", 3.0), ("dead_zone_neg_deg", -2.0),
                       ("zero_load_pos_deg", 0.0), ("zero_load_neg_deg", 0.0)):
        assert np.allclose(moved.values[:, f.column(name)],
                           f.values[:, f.column(name)] + move)


def test_a_saved_version_compensates_like_the_online_zero_load_points(profile: Any) -> None:
    offsets, gains, zero = ((3.0, 2.0), (1.0, -1.0)), ((1.3, 1.2), (1.0, 1.5)), ((0.0, 0.5),
                                                                                (1.0, 0.0))
    live = build_compensator(profile, "ours", 0.004)
    worker = OnlineWorker(live, 0.004, ROW_COLUMNS)
    worker.published = (1, offsets, tuple(  # type: ignore[assignment]
        shifted_knob(worker.base_knobs[k], offsets[k], gains[k], zero[k]) for k in (0, 1)))
    worker.observe(worker_row(), True)
    saved = build_compensator(profile_with_offsets(profile, offsets, gains=gains,
                                                   zero_loads=zero), "ours", 0.004)
    assert largest_command_difference_deg(live, saved) < 1e-6


def test_switching_off_restores_the_profiles_zero_load_points(profile: Any) -> None:
    worker, comp, base = make_worker(profile)
    worker.zero_loads = ((1.0, 1.0), (0.0, 0.0))
    worker.set_enabled(False)
    worker.observe(worker_row(), True)
    assert worker.zero_loads == ((0.0, 0.0), (0.0, 0.0)) and comp.knobs[0] is base[0]


def test_the_status_reports_the_zero_load_points_in_force(profile: Any) -> None:
    worker, _, _ = make_worker(profile)
    worker.zero_loads = ((1.0, 0.5), (0.0, 0.0))
    status = worker.status()
    assert status["zero_load_offsets_deg"] == [[1.0, 0.5], [0.0, 0.0]]
    assert status["edges"]["phi1_pos"]["zero_load_offset_deg"] == 0.0
