"""The identification worker: what it answers beside the grid point, and how its failures end a
protocol (sweeps from the built-in tendon-sheath plant on the tests' small lockstep runner)."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest
from support.calibration import LockstepPlantRunner

from simrig.plants.capstan.tendon_sheath import make_tendon_sheath_plant
from tsmd.calibration import CalibrationError, Protocol, Sweep
from tsmd.calibration.estimate import point_estimates
from tsmd.calibration.identify import settle_rule_backlash
from tsmd.calibration.lag import estimate_lag_s
from tsmd.calibration.resweep import pooled
from tsmd.calibration.run import SweepRuns, run_sweeps
from tsmd.calibration.tension_play_fit import SweepPrefit, sweeps_from_points, with_prefit

PERIOD_S = 0.004
SHORT_SWEEP = Sweep(0, 0.0, 90.0, 0.1, 1.5, "triangle")


@pytest.fixture(scope="module")
def isolated() -> SweepRuns:
    return run_sweeps(LockstepPlantRunner(make_tendon_sheath_plant(), PERIOD_S),
                      Protocol("one", (SHORT_SWEEP,)), isolate=True, live_loop=False)


def test_worker_answers_the_settle_rule_backlash_of_the_sweeps_own_signals(
        isolated: SweepRuns) -> None:
    point = isolated.points[0]
    assert point.prefit is not None
    b_pos, b_neg = settle_rule_backlash(point.result.data)
    assert (point.prefit.backlash_pos_deg, point.prefit.backlash_neg_deg) == (b_pos, b_neg)
    assert math.isfinite(b_pos) and math.isfinite(b_neg)


def test_worker_answers_the_drives_lag_of_the_sweeps_own_signals(isolated: SweepRuns) -> None:
    point = isolated.points[0]
    data = point.result.data
    assert point.prefit is not None
    assert point.prefit.lag_s == estimate_lag_s(data.t_s, data.cmd_deg, data.pos_deg)


def test_identification_in_this_process_leaves_the_prefit_to_the_fit() -> None:
    here = run_sweeps(LockstepPlantRunner(make_tendon_sheath_plant(), PERIOD_S),
                      Protocol("one", (SHORT_SWEEP,)))
    assert here.points[0].prefit is None


def test_tension_play_fit_takes_the_prefit_already_found(isolated: SweepRuns) -> None:
    marked = replace(isolated.points[0], prefit=SweepPrefit(11.0, 12.0, 0.25))
    (sweep,) = sweeps_from_points([marked], 0)
    assert (sweep.settle_backlash_deg, sweep.lag_s) == ((11.0, 12.0), 0.25)


def test_tension_play_fit_takes_the_backlash_of_the_profiles_rule(isolated: SweepRuns) -> None:
    marked = replace(isolated.points[0], prefit=SweepPrefit(11.0, 12.0, 0.25))
    (sweep,) = sweeps_from_points([marked], 0)
    est = marked.result.estimate
    assert (sweep.backlash_pos_deg, sweep.backlash_neg_deg) == \
        (est("backlash_pos_deg"), est("backlash_neg_deg"))


def test_tension_play_fit_analyses_a_point_without_a_prefit(isolated: SweepRuns) -> None:
    bare = replace(isolated.points[0], prefit=None)
    (sweep,) = sweeps_from_points([bare], 0)
    assert sweep.settle_backlash_deg == settle_rule_backlash(bare.result.data)


def test_tension_play_fit_takes_the_edges_uncertainty_the_calibration_gate_uses(
        isolated: SweepRuns) -> None:
    (sweep,) = sweeps_from_points([isolated.points[0]], 0)
    (est,) = point_estimates([isolated.points[0].result])
    assert sweep.dead_zone_u95_deg == (est["dead_zone_pos_deg"].u95_deg,
                                       est["dead_zone_neg_deg"].u95_deg)


def test_a_pooled_resweep_keeps_the_first_sweeps_prefit(isolated: SweepRuns) -> None:
    first = replace(isolated.points[0], prefit=SweepPrefit(11.0, 12.0, 0.25))
    again = with_prefit(replace(isolated.points[0], prefit=None))
    assert pooled(first, again).prefit == SweepPrefit(11.0, 12.0, 0.25)


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


def test_a_prefit_that_fails_in_the_worker_is_left_to_the_fit(
        isolated: SweepRuns, monkeypatch: pytest.MonkeyPatch) -> None:
    import tsmd.calibration.tension_play_fit as fit
    from tsmd.calibration.run import _identify_detached

    def broken(data: object) -> SweepPrefit:
        raise ValueError("no reversal")

    monkeypatch.setattr(fit, "prefit_sweep", broken)
    rec = isolated.points[0].recording
    assert rec is not None
    assert _identify_detached(rec, None, "sweep").prefit is None
