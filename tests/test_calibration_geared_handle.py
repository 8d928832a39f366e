"""A geared handle: the motor current climbs the loaded branch in steps, one per tooth of mesh,
flat between them; the dead zone is still the flat run at the slack level (session 18)."""

from __future__ import annotations

import numpy as np
import pytest
from support.calibration import LockstepPlantRunner

from simrig.analysis import measure_dead_zone_backlash
from simrig.family import family_member
from tsmd.calibration import Protocol, Sweep, identify_sweep
from tsmd.calibration.identify import IdentifyOptions
from tsmd.calibration.pieces import constant_phase
from tsmd.calibration.player import sweep_metadata
from tsmd.calibration.protocol import sweep_run
from tsmd.recording import Recording

PERIOD_S = 0.004
FAST_SWEEP = Sweep(0, 0.0, 90.0, 0.06, 2.0, "sine")
"""The fast protocol's rate: at 0.06 Hz the warmgear plant's loaded steps are long and flat."""


@pytest.fixture(scope="module")
def geared_rec() -> Recording:
    runner = LockstepPlantRunner(family_member("warmgear", 0).build(), PERIOD_S)
    run = sweep_run(FAST_SWEEP, np.zeros(2), PERIOD_S, Protocol("t", (FAST_SWEEP,)))
    rec = runner.run(run.t_s, run.q_deg)
    rec.metadata.update(sweep_metadata(FAST_SWEEP, float(run.t_s[run.sweep_start])))
    return rec


def test_a_geared_handles_loaded_steps_are_not_taken_for_the_dead_zone(
        geared_rec: Recording) -> None:
    start = float(geared_rec.metadata["calibration_sweep_start_s"])
    result = identify_sweep(geared_rec["t"], geared_rec["cmd1"], geared_rec["pos1"],
                            geared_rec["cur1"], sweep_start_s=start)
    m = geared_rec["t"] >= start - 1.0
    truth = measure_dead_zone_backlash(geared_rec["pos1"][m], geared_rec["tip1"][m],
                                       threshold_deg=0.5)
    for name in ("dead_zone_pos_deg", "dead_zone_neg_deg"):
        assert result.values[name], name
        assert max(abs(v - getattr(truth, name)) for v in result.values[name]) < 8.0, name


def _two_flat_runs(low_A: float, high_A: float) -> tuple[list[tuple[int, int]], np.ndarray]:
    """Pieces and current on the grid: 20 deg flat at ``low_A``, a ramp, 20 deg flat at
    ``high_A``."""
    n = round(20.0 / IdentifyOptions().grid_step_deg)
    yg = np.concatenate([np.full(n, low_A), np.linspace(low_A, high_A, n), np.full(n, high_A)])
    return [(0, n), (n, 2 * n), (2 * n, 3 * n)], yg


def test_a_flat_run_far_above_the_slack_level_is_passed_over() -> None:
    opts = IdentifyOptions()
    pieces, yg = _two_flat_runs(0.02, 0.15)
    flat = [True, False, True]
    assert constant_phase(pieces, flat, opts.grid_step_deg, opts) == pieces[2]
    assert constant_phase(pieces, flat, opts.grid_step_deg, opts, yg,
                          loaded_swing=0.16) == pieces[0]


def test_flat_runs_near_the_slack_level_keep_the_last_one() -> None:
    opts = IdentifyOptions()
    pieces, yg = _two_flat_runs(0.016, 0.034)
    assert constant_phase(pieces, [True, False, True], opts.grid_step_deg, opts, yg,
                          loaded_swing=0.16) == pieces[2]
