"""The data sheet chooses the play step per knob on its own unit (tsmd.datasheet_play_step,
session 24): on where a step shows in nearly every half-cycle, lies within the target of the
tip's backlash and reads it closer than the rule's end; off where no step shows or the rule
already reads the tip."""

from __future__ import annotations

import math

from support.play_step import PLAY_DEG, sweep
from support.profiles import DEVICE

from tsmd.calibration.assemble import GridPoint, QualityReport, cross_check_device
from tsmd.calibration.identify import identify_sweep
from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.run import device_options
from tsmd.datasheet_play_step import PlayStepScore, play_step_scores, with_play_step
from tsmd.profile import load_device_model
from tsmd.tracked_calibration import ProtocolRun


def run_with_step(step_A: float) -> ProtocolRun:
    """One fast calibration whose phi1 sweep (phi2 at 0) shows the step, identified by the
    rule alone."""
    t, q, current = sweep(step_A)
    point = GridPoint(0, 0.0, identify_sweep(t, q, q, current, IdentifyOptions()))
    return ProtocolRun("fast", True, "", [point], [], 0.0, 0.0, 0.0, 0)


def truth(backlash_deg: float) -> dict[tuple[int, float], dict[str, float]]:
    return {(0, 0.0): {"backlash_pos_deg": backlash_deg, "backlash_neg_deg": backlash_deg}}


def test_a_step_at_the_tips_release_is_chosen() -> None:
    phi1, phi2 = play_step_scores([run_with_step(-0.010)], load_device_model(DEVICE),
                                  truth(PLAY_DEG + 0.5))
    assert phi1.half_cycles > 0 and phi1.found == phi1.half_cycles and phi1.chosen
    assert phi2.half_cycles == 0 and not phi2.chosen


def test_no_step_in_the_current_keeps_the_rule() -> None:
    phi1, _ = play_step_scores([run_with_step(0.0)], load_device_model(DEVICE),
                               truth(PLAY_DEG + 0.5))
    assert phi1.found == 0 and not phi1.chosen


def test_a_tip_released_where_the_rule_ends_keeps_the_rule() -> None:
    phi1, _ = play_step_scores([run_with_step(-0.010)], load_device_model(DEVICE), truth(3.0))
    assert phi1.found > 0 and not phi1.chosen


def test_steps_found_in_too_few_half_cycles_keep_the_rule() -> None:
    assert not PlayStepScore(0, 10, 8, 8, 0.5, 9.0).chosen
    assert PlayStepScore(0, 10, 9, 9, 0.5, 9.0).chosen


def test_steps_off_the_tip_keep_the_rule() -> None:
    assert not PlayStepScore(0, 10, 10, 8, 1.5, 9.0).chosen


def test_the_choice_is_written_per_knob_and_off_is_absent() -> None:
    scores = (PlayStepScore(0, 10, 10, 10, 0.5, 9.0), PlayStepScore(1, 10, 0, 0, math.nan, 2.0))
    device = with_play_step(load_device_model(DEVICE), scores)
    assert (device.knobs[0].backlash_play_step, device.knobs[1].backlash_play_step) == (True, None)
    phi1, phi2 = device_options(None, device)
    assert phi1.backlash_play_step and not phi2.backlash_play_step


def play_warnings(on: bool) -> list[str]:
    scores = tuple(PlayStepScore(k, 10, 10 if on else 0, 10 if on else 0, 0.5, 9.0)
                   for k in (0, 1))
    device = with_play_step(load_device_model(DEVICE), scores)
    report = QualityReport()
    cross_check_device(run_with_step(-0.010).points, device, report)
    return [w for w in report.warnings if "play closes" in w]


def test_a_calibration_under_the_play_step_warns_that_the_tip_may_let_go_earlier() -> None:
    assert len(play_warnings(True)) == 1


def test_without_the_play_step_no_such_warning() -> None:
    assert play_warnings(False) == []
