"""The identification worker: what it answers beside the grid point, and how its failures end a
protocol (sweeps from the built-in tendon-sheath plant on the tests' small lockstep runner)."""

from __future__ import annotations

import math

import pytest
from support.calibration import LockstepPlantRunner

from simrig.plants.capstan.tendon_sheath import make_tendon_sheath_plant
from tsmd.calibration import CalibrationError, Protocol, Sweep
from tsmd.calibration.identify import settle_rule_backlash
from tsmd.calibration.resweep import pooled
from tsmd.calibration.run import SweepRuns, run_sweeps
from tsmd.calibration.tension_play_fit import sweeps_from_points, with_settle_backlash

PERIOD_S = 0.004
SHORT_SWEEP = Sweep(0, 0.0, 90.0, 0.1, 1.5, "triangle")


@pytest.fixture(scope="module")
def isolated() -> SweepRuns:
    return run_sweeps(LockstepPlantRunner(make_tendon_sheath_plant(), PERIOD_S),
                      Protocol("one", (SHORT_SWEEP,)), isolate=True, live_loop=False)


def test_worker_answers_the_settle_rule_backlash_of_the_sweeps_own_signals(
        isolated: SweepRuns) -> None:
    point = isolated.points[0]
    assert point.settle_backlash_deg is not None
    assert point.settle_backlash_deg == settle_rule_backlash(point.result.data)
    assert all(math.isfinite(b) for b in point.settle_backlash_deg)


def test_identification_in_this_process_leaves_the_settle_backlash_to_the_fit() -> None:
    here = run_sweeps(LockstepPlantRunner(make_tendon_sheath_plant(), PERIOD_S),
                      Protocol("one", (SHORT_SWEEP,)))
    assert here.points[0].settle_backlash_deg is None


def test_tension_play_fit_takes_the_settle_backlash_already_found(isolated: SweepRuns) -> None:
    from dataclasses import replace

    marked = replace(isolated.points[0], settle_backlash_deg=(11.0, 12.0))
    (sweep,) = sweeps_from_points([marked], 0)
    assert (sweep.backlash_pos_deg, sweep.backlash_neg_deg) == (11.0, 12.0)


def test_tension_play_fit_analyses_a_point_without_a_settle_backlash(isolated: SweepRuns) -> None:
    from dataclasses import replace

    bare = replace(isolated.points[0], settle_backlash_deg=None)
    (sweep,) = sweeps_from_points([bare], 0)
    assert (sweep.backlash_pos_deg, sweep.backlash_neg_deg) == \
        settle_rule_backlash(bare.result.data)


def test_a_pooled_resweep_keeps_the_first_sweeps_settle_backlash(isolated: SweepRuns) -> None:
    from dataclasses import replace

    first = replace(isolated.points[0], settle_backlash_deg=(11.0, 12.0))
    again = with_settle_backlash(replace(isolated.points[0], settle_backlash_deg=None))
    assert pooled(first, again).settle_backlash_deg == (11.0, 12.0)


def test_a_sweep_the_worker_cannot_identify_stops_the_protocol_with_one_line() -> None:
    silent = LockstepPlantRunner(make_tendon_sheath_plant(), PERIOD_S, current_noise_A=0.0,
                                 amps_per_Nm=0.0, motor_friction_A=0.0)
    proto = Protocol("two", (SHORT_SWEEP, Sweep(0, 30.0, 90.0, 0.1, 1.5, "triangle")))
    with pytest.raises(CalibrationError) as caught:
        run_sweeps(silent, proto, isolate=True, live_loop=False)
    message = str(caught.value)
    assert "\n" not in message
    assert "current is constant" in message
    assert SHORT_SWEEP.label in message
