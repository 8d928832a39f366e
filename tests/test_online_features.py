"""Features of the motor current during ordinary motion (tsmd.online.features, .segment)."""

from __future__ import annotations

import numpy as np
import pytest
from support.online import ENGAGE_A, FRICTION_A, SLOPE_A_PER_DEG, knob_current

from tsmd.online.features import (
    LoadedRamp,
    Rejected,
    Stroke,
    loaded_ramp,
    relocated_edge_deg,
)
from tsmd.online.segment import StrokeSegmenter


def rising_stroke(edge_deg: float, *, noise_A: float = 0.003, seed: int = 0,
                  start_deg: float = -20.0, end_deg: float = 60.0,
                  lag_deg: float = 0.0) -> Stroke:
    rng = np.random.default_rng(seed)
    pos = np.arange(start_deg, end_deg, 0.1)
    cur = np.array([knob_current(p, 10.0, edge_deg, -edge_deg) for p in pos])
    cur += noise_A * rng.standard_normal(pos.size)
    slip = pos - start_deg
    return Stroke(0, 1, np.arange(pos.size) * 0.01, pos + lag_deg, pos, cur,
                  np.zeros(pos.size), slip)


def level_at_edge() -> float:
    return FRICTION_A + ENGAGE_A


def mean_crossing(edge_deg: float, seeds: range = range(8)) -> float:
    """One stroke's crossing scatters by ~0.3 deg (3 mA noise); the mean over strokes."""
    found = []
    for seed in seeds:
        ramp = loaded_ramp(rising_stroke(edge_deg, seed=seed), edge_deg)
        assert isinstance(ramp, LoadedRamp)
        found.append(ramp.crossing_deg(level_at_edge()))
    return float(np.mean(found))


def test_ramp_crosses_the_engagement_level_at_the_edge() -> None:
    assert mean_crossing(20.0) == pytest.approx(20.0, abs=0.25)
    ramp = loaded_ramp(rising_stroke(20.0), 20.0)
    assert isinstance(ramp, LoadedRamp)
    assert ramp.slope_A_per_deg == pytest.approx(SLOPE_A_PER_DEG, rel=0.1)


def test_a_moved_edge_moves_the_crossing_by_as_much() -> None:
    shift = mean_crossing(24.0, range(10, 18)) - mean_crossing(20.0)
    assert shift == pytest.approx(4.0, abs=0.35)


def test_spikes_do_not_move_the_ramp() -> None:
    stroke = rising_stroke(20.0, seed=2)
    spiky = stroke.current_A.copy()
    spiky[::37] += 0.3
    with_spikes = Stroke(0, 1, stroke.t_s, stroke.cmd_deg, stroke.pos_deg, spiky,
                         stroke.other_deg, stroke.slip_deg)
    ramp = loaded_ramp(with_spikes, 20.0)
    clean = loaded_ramp(stroke, 20.0)
    assert isinstance(ramp, LoadedRamp) and isinstance(clean, LoadedRamp)
    assert ramp.crossing_deg(level_at_edge()) == pytest.approx(
        clean.crossing_deg(level_at_edge()), abs=0.1)


def test_a_motor_that_lags_its_command_is_a_stall() -> None:
    result = loaded_ramp(rising_stroke(20.0, lag_deg=8.0), 20.0)
    assert isinstance(result, Rejected) and result.stall


def test_a_stroke_that_starts_beyond_the_edge_is_no_engagement() -> None:
    result = loaded_ramp(rising_stroke(20.0, start_deg=25.0), 20.0)
    assert isinstance(result, Rejected) and not result.stall
    assert "dead zone" in result.reason


def test_a_stroke_that_turns_back_early_gives_no_ramp() -> None:
    result = loaded_ramp(rising_stroke(20.0, end_deg=27.0), 20.0)
    assert isinstance(result, Rejected)


def test_reference_ramp_relocates_a_moved_edge() -> None:
    stroke = rising_stroke(25.0, seed=3)
    found = relocated_edge_deg(stroke, 20.0, level_at_edge(), SLOPE_A_PER_DEG)
    assert found == pytest.approx(25.0, abs=1.0)


def test_falling_stroke_gives_the_negative_edge() -> None:
    rising = rising_stroke(20.0, seed=4)
    pos = -rising.pos_deg
    cur = np.array([knob_current(p, -10.0, 20.0, -20.0) for p in pos])
    stroke = Stroke(0, -1, rising.t_s, pos, pos, cur, rising.other_deg, rising.slip_deg)
    ramp = loaded_ramp(stroke, -20.0)
    assert isinstance(ramp, LoadedRamp) and ramp.side == -1
    assert ramp.crossing_deg(level_at_edge()) == pytest.approx(-20.0, abs=0.3)


def test_segmenter_cuts_strokes_at_reversals_of_the_command() -> None:
    seg = StrokeSegmenter(0)
    t = np.arange(0.0, 40.0, 0.004)
    cmd = 60.0 * np.sin(2 * np.pi * 0.05 * t)
    strokes = [s for s in (seg.push(ti, c, c, 0.0, 0.0) for ti, c in zip(t, cmd, strict=True))
               if s is not None]
    assert [s.direction for s in strokes] == [1, -1, 1, -1]  # turns at 5, 15, 25, 35 s
    assert strokes[1].pos_deg.max() == pytest.approx(59.0, abs=1.5)


def test_slip_restarts_after_the_knob_stood_still() -> None:
    seg = StrokeSegmenter(0)
    t = np.arange(0.0, 6.0, 0.004)
    pos = np.where(t < 2.0, 10.0 * t, np.where(t < 3.0, 20.0, 20.0 + 10.0 * (t - 3.0)))
    for ti, p in zip(t, pos, strict=True):
        seg.push(ti, p, p, 0.0, 0.0)
    stroke = seg.push(6.0, 0.0, 0.0, 0.0, 0.0)  # turn back: the stroke comes out
    assert stroke is not None
    after = stroke.pos_deg > 20.5
    assert stroke.slip_deg[after].min() < 1.0  # counted again from the restart at 20 deg
    assert stroke.slip_deg[~after].max() == pytest.approx(20.0, abs=0.5)


def test_the_real_probe_shows_a_loaded_ramp_of_the_same_slope_in_every_acquisition() -> None:
    from tsmd.calibration import identify_sweep
    from tsmd.tee import default_tee_dir, load_tee_acquisition

    files = sorted(default_tee_dir().glob("motor1_current60__*_acquisition.csv"))
    if not files:
        pytest.skip(f"no TEE data in {default_tee_dir()} (set TSMD_TEE_DATA)")
    slopes = []
    for f in files:
        rec = load_tee_acquisition(f)
        t, cmd, pos, cur = rec["t"], rec["cmd1"], rec["pos1"], rec["cur1"]
        edge = identify_sweep(t, cmd, pos, cur).estimate("dead_zone_pos_deg")
        seg = StrokeSegmenter(0)
        for sample in zip(t, cmd, pos, cur, np.zeros_like(t), strict=True):
            stroke = seg.push(*(float(v) for v in sample))
            if stroke is not None and stroke.direction > 0:
                ramp = loaded_ramp(stroke, edge)
                assert isinstance(ramp, LoadedRamp), getattr(ramp, "reason", "")
                slopes.append(ramp.slope_A_per_deg)
    assert len(slopes) == len(files)
    assert min(slopes) > 0 and max(slopes) / min(slopes) < 1.5
