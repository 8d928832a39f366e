"""The backlash rules scored half-cycle by half-cycle on the sheet's unit (session 21,
tsmd.datasheet_rule_halves): a half-cycle's B against the tip tracked in the same sweep, and a
rule whose grid medians hide misread half-cycles loses the choice."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from support.profiles import DEVICE

from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import HalfCycle, SweepResult
from tsmd.datasheet_rule import RuleScore, choose_rules, knee_choice
from tsmd.datasheet_rule_halves import half_cycle_errors, placed, tip_backlash_deg
from tsmd.profile import DeviceModel, load_device_model

RATE_HZ = 100.0
PLAY_DEG = 12.0


def sweep_with_play(play_deg: float = PLAY_DEG) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One rise to +90 and back to -90 deg; the tip follows the knob once ``play_deg`` of
    travel after each reversal is taken up (t, knob, tip)."""
    up, down = np.linspace(0.0, 90.0, 900), np.linspace(90.0, -90.0, 1800)[1:]
    knob = np.concatenate([up, down])
    tip = np.concatenate([0.8 * up, 0.8 * np.minimum(down + play_deg, 90.0)])
    return np.arange(knob.size) / RATE_HZ, knob, tip


def result_with(backlash_deg: float) -> tuple[SweepResult, np.ndarray, np.ndarray]:
    t, knob, tip = sweep_with_play()
    zeros = np.zeros_like(t)
    data = Conditioned(t, knob, knob, zeros, zeros, RATE_HZ, 1e-3, 1e-3, ())
    halves = (HalfCycle(1, 0, 900, False),
              HalfCycle(-1, 899, t.size, True, backlash_deg=backlash_deg))
    return SweepResult(data, halves), t, tip


def test_the_tips_backlash_is_the_travel_until_it_moves_the_threshold() -> None:
    _, knob, tip = sweep_with_play()
    found = tip_backlash_deg(knob[899:], tip[899:], -1, 0.25)
    # the tip moves 1 deg (the truth's threshold) 1.25 knob deg after the play is taken up
    assert abs(found - (PLAY_DEG + 1.0 / 0.8)) <= 0.5


def test_a_half_cycles_error_is_its_b_minus_the_tips() -> None:
    result, t, tip = result_with(PLAY_DEG + 6.0)
    errors = half_cycle_errors(result, t, tip, 0.25)
    assert len(errors) == 1  # the first half-cycle starts at no reversal
    assert abs(errors[0] - (6.0 - 1.0 / 0.8)) <= 0.5


def test_a_half_cycle_without_b_is_a_miss() -> None:
    result, t, tip = result_with(math.nan)
    errors = half_cycle_errors(result, t, tip, 0.25)
    assert len(errors) == 1 and placed(errors) == 0


def sheet() -> DeviceModel:
    base = load_device_model(DEVICE)
    knobs = tuple(dataclasses.replace(k, backlash_settle_fraction=0.95,
                                      backlash_release_slope_ratio=0.1,
                                      backlash_release_line_share=0.94,
                                      backlash_release_local_share=0.99) for k in base.knobs)
    return dataclasses.replace(base, knobs=(knobs[0], knobs[1]))


def scored(rule: str, knob: int, within: int, half_placed: int) -> RuleScore:
    return RuleScore(rule, knob, within, 56, 1.0, 3.0, 2, 2, None, half_placed, 24)


def test_a_rule_whose_half_cycles_miss_loses_despite_one_more_grid_value() -> None:
    scores = [scored("line", 0, 44, 14), scored("local", 0, 43, 24),
              scored("line", 1, 50, 24), scored("local", 1, 43, 24)]
    chosen = choose_rules(sheet(), scores)
    assert [k.backlash_release_rule for k in chosen.knobs] == ["local", "line"]


def test_the_knee_is_still_chosen_on_the_grid_values_alone() -> None:
    rules = [scored("local", 0, 50, 10), scored("local", 1, 50, 24)]
    knee = [scored("knee", 0, 50, 24), scored("knee", 1, 50, 10)]
    base = sheet()
    local = [dataclasses.replace(k, backlash_release_rule="local") for k in base.knobs]
    with_local = dataclasses.replace(base, knobs=(local[0], local[1]))
    chosen = knee_choice(with_local, rules, knee)
    assert [k.backlash_knee for k in chosen.knobs] == [True, True]
