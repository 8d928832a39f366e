"""The backlash rules scored half-cycle by half-cycle on the sheet's unit (session 21,
tsmd.datasheet_rule_halves): a half-cycle's B against the tip tracked in the same sweep, and a
rule that misreads more half-cycles loses whatever its grid medians placed."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from support.profiles import DEVICE

from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import HalfCycle, SweepResult
from tsmd.datasheet_rule import RuleScore, choose_rules
from tsmd.datasheet_rule_halves import HalfRead, half_cycle_reads, tip_backlash_deg
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


def test_each_half_cycle_after_a_reversal_pairs_the_rules_b_with_the_tips() -> None:
    result, t, tip = result_with(PLAY_DEG + 6.0)
    reads = half_cycle_reads(result, t, tip, 0.25)
    assert len(reads) == 1  # the first half-cycle starts at no reversal
    assert reads[0].backlash_deg == PLAY_DEG + 6.0
    assert abs(reads[0].tip_deg - (PLAY_DEG + 1.0 / 0.8)) <= 0.5


def test_a_b_off_by_more_than_the_tips_own_is_a_misread_not_a_near_miss() -> None:
    assert HalfRead(37.0, 12.0).misread and not HalfRead(37.0, 12.0).placed
    assert not HalfRead(19.0, 12.0).misread and not HalfRead(19.0, 12.0).placed
    assert HalfRead(13.5, 12.0).placed


def test_a_missing_b_is_neither_placed_nor_misread() -> None:
    result, t, tip = result_with(math.nan)
    (read,) = half_cycle_reads(result, t, tip, 0.25)
    assert not read.placed and not read.misread


def sheet() -> DeviceModel:
    base = load_device_model(DEVICE)
    knobs = tuple(dataclasses.replace(k, backlash_settle_fraction=0.95,
                                      backlash_release_slope_ratio=0.1,
                                      backlash_release_line_share=0.94,
                                      backlash_release_local_share=0.99) for k in base.knobs)
    return dataclasses.replace(base, knobs=(knobs[0], knobs[1]))


def scored(rule: str, knob: int, within: int, misread: int) -> RuleScore:
    return RuleScore(rule, knob, within, 56, 1.0, 3.0, 2, 2, None, 24 - misread, misread, 24)


def test_a_rule_that_misreads_more_half_cycles_loses_despite_more_values() -> None:
    scores = [scored("swing", 0, 49, 2), scored("local", 0, 43, 0),
              scored("swing", 1, 34, 0), scored("local", 1, 27, 0)]
    chosen = choose_rules(sheet(), scores)
    assert [k.backlash_release_rule for k in chosen.knobs] == ["local", "swing"]


def test_among_rules_misreading_equally_the_values_decide() -> None:
    scores = [scored("line", k, 44, 3) for k in (0, 1)] + [
        scored("local", 0, 46, 3), scored("local", 1, 43, 3)]
    chosen = choose_rules(sheet(), scores)
    assert [k.backlash_release_rule for k in chosen.knobs] == ["local", "line"]
