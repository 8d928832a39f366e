"""What the calibration refuses, each reason named, and the bad data it recovers from.

Sweeps come from the built-in tendon-sheath plant through the small lockstep runner
(tests/support/calibration.py); faults are made on the recorded signals as a faulty sensor
or coupling would make them.
"""

from __future__ import annotations

import numpy as np
import pytest
from support.calibration import sweep_recording

from tsmd.calibration import CalibrationError, Sweep, identify_sweep
from tsmd.calibration.estimate import point_estimates
from tsmd.calibration.health import check_sensor, check_slips, find_slip
from tsmd.calibration.sweep_result import SweepResult
from tsmd.recording import Recording

SWEEP = Sweep(0, 0.0, 90.0, 0.1, 2.0, "triangle")


@pytest.fixture(scope="module")
def rec() -> Recording:
    return sweep_recording(SWEEP)


def _identify(rec: Recording, current: np.ndarray | None = None,
              n: int | None = None) -> SweepResult:
    cur = rec["cur1"] if current is None else current
    stop = len(rec) if n is None else n
    return identify_sweep(rec["t"][:stop], rec["cmd1"][:stop], rec["pos1"][:stop], cur[:stop],
                          sweep_start_s=float(rec.metadata["calibration_sweep_start_s"]))


def test_noise_and_spikes_move_each_parameter_less_than_its_stated_uncertainty(
        rec: Recording) -> None:
    clean = _identify(rec)
    rng = np.random.default_rng(7)
    cur = rec["cur1"] + rng.normal(0.0, 0.004, len(rec))
    cur += (rng.random(len(rec)) < 0.01) * rng.choice([-1.0, 1.0], len(rec)) * 0.1
    noisy = _identify(rec, cur)
    assert any("spikes removed" in n for n in noisy.data.notes)
    (stated,) = point_estimates([noisy])
    for name, values in clean.values.items():
        assert values, name
        assert np.isfinite(stated[name].u95_deg), name
        assert abs(stated[name].value - clean.estimate(name)) <= stated[name].u95_deg, name


def test_missing_samples_are_filled_and_change_nothing_that_matters(rec: Recording) -> None:
    cur = rec["cur1"].copy()
    rng = np.random.default_rng(1)
    for start in rng.integers(100, len(rec) - 100, 30):
        cur[start:start + 5] = np.nan
    holed = _identify(rec, cur)
    assert any("missing current samples interpolated" in n for n in holed.data.notes)
    clean = _identify(rec)
    for name in clean.values:
        assert abs(holed.estimate(name) - clean.estimate(name)) < 1.0, name


def test_a_half_cycle_cut_short_gives_what_it_reached_and_the_rest_stands(
        rec: Recording) -> None:
    start = float(rec.metadata["calibration_sweep_start_s"])
    # Cut the recording 5 s into the last half-cycle (of 5 s): its edge is never reached.
    n = int(np.searchsorted(rec["t"], start + 17.0))
    cut = _identify(rec, n=n)
    full = _identify(rec)
    assert len(cut.values["dead_zone_neg_deg"]) == len(full.values["dead_zone_neg_deg"]) - 1
    assert cut.estimate("dead_zone_pos_deg") == pytest.approx(
        full.estimate("dead_zone_pos_deg"), abs=1.0)


def test_a_current_that_never_changes_is_no_feedback(rec: Recording) -> None:
    with pytest.raises(CalibrationError, match="no current feedback"):
        _identify(rec, np.zeros(len(rec)))


def test_a_current_of_pure_noise_is_no_current_signal(rec: Recording) -> None:
    noise = np.random.default_rng(0).normal(0.0, 0.01, len(rec))
    with pytest.raises(CalibrationError, match="no current signal"):
        _identify(rec, noise)


def test_a_sensor_stuck_at_one_reading_is_refused_with_when(rec: Recording) -> None:
    cur = rec["cur1"].copy()
    cur[3000:4500] = cur[3000]
    with pytest.raises(CalibrationError, match=r"current sensor is stuck at .* from t="):
        _identify(rec, cur)


def test_a_clipped_sensor_is_refused_as_saturated(rec: Recording) -> None:
    cur = rec["cur1"]
    limit = 0.5 * float(np.max(np.abs(cur)))
    with pytest.raises(CalibrationError, match="saturated"):
        _identify(rec, np.clip(cur, -limit, limit))


def test_a_large_reading_that_recurs_with_larger_ones_beyond_it_is_no_clipping(
        rec: Recording) -> None:
    # A quantised current dwelling near its peak: one large value in many separate stretches,
    # as often as a clipped one, but the sensor also reads past it.
    cur = np.round(rec["cur1"] / 0.002) * 0.002
    lo, hi = np.quantile(cur, [0.02, 0.06])
    cur[(cur >= lo) & (cur <= hi)] = lo
    assert np.count_nonzero(cur == lo) >= 0.02 * cur.size and np.any(cur < lo)
    check_sensor(rec["t"], rec["pos1"], cur)


def _load(drop_at_deg: float | None) -> tuple[np.ndarray, np.ndarray, int]:
    grid = np.arange(0.0, 60.0, 0.25)
    load = np.maximum(grid - 20.0, 0.0) * 0.01
    load += np.random.default_rng(0).normal(0.0, 0.002, grid.size)
    if drop_at_deg is not None:
        load[grid > drop_at_deg] -= 0.15  # the coupling lets go
    return grid, load, int(np.searchsorted(grid, 20.0))


def test_a_loaded_current_that_drops_while_moving_on_is_found() -> None:
    grid, load, edge = _load(45.0)
    assert "drops by" in (find_slip(grid, load, edge, 0.002) or "")


def test_a_loaded_current_that_keeps_rising_is_no_slip() -> None:
    grid, load, edge = _load(None)
    assert find_slip(grid, load, edge, 0.002) is None


def test_a_knob_that_slips_on_most_strokes_is_refused_naming_it() -> None:
    with pytest.raises(CalibrationError, match=r"the knob slips .* on 3 of 4 loaded strokes"):
        check_slips(["drops by 150 mA", None, "drops by 140 mA", "drops by 160 mA"])


def test_one_disturbed_stroke_is_not_a_slip() -> None:
    check_slips([None, "drops by 80 mA", None, None])
