"""The compliance sheet's figure when a light load's lost motion carries a gear's play."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from support.gap_play import play_at_light_load

from tsmd.gap import compliance
from tsmd.gap.crosstest import make_session
from tsmd.gap.data import GapSeries, series_from_recording
from tsmd.gap.presets import PRESETS
from tsmd.gap.reversal import TRAVEL_GRID_DEG, Reversals

RATE_HZ = 50.0


@functools.cache
def _series(unit: int, case: str = "none") -> tuple[GapSeries, ...]:
    recs = make_session(PRESETS["capstan"], case, 4.0, RATE_HZ, unit,
                        unit_variation=0.0 if unit == 0 else 0.1)
    return tuple(series_from_recording(r, f"{case}-{unit}-{i}")
                 for i, r in enumerate(recs) if "segments" in r.metadata)


def _units(with_play: bool) -> list[list[GapSeries]]:
    five = play_at_light_load(_series(5)) if with_play else list(_series(5))
    return [list(_series(0)), five, list(_series(6))]


def test_a_gear_play_at_the_light_load_does_not_widen_the_units_spread() -> None:
    sheet = compliance.sheet_from_units(_units(with_play=True))
    assert sheet is not None
    assert np.exp(np.sqrt(sheet.allowance_log_var[0])) < 1.0 + compliance.TOLERANCE


def test_a_model_whose_lost_motion_grows_with_the_load_keeps_the_load_contrast() -> None:
    sheet = compliance.sheet_from_units(_units(with_play=False))
    assert sheet is not None and sheet.figure == "load contrast"


@pytest.mark.parametrize(("case", "named"), [("compliance", True), ("none", False)])
def test_compliance_is_named_on_the_release_against_such_a_sheet(case: str,
                                                                  named: bool) -> None:
    sheet = compliance.sheet_from_units(_units(with_play=True))
    assert sheet is not None and sheet.figure == "release"
    score = compliance.compliance_score(list(_series(7, case)), sheet, 7)
    assert score is not None and score.significant is named


def test_the_release_reads_the_travel_per_ampere_whatever_the_play_before_it() -> None:
    def reversals(play_deg: float) -> Reversals:
        # the current falls from 0.20 A to 0.05 A over 3 deg of knob after the play
        cur = np.interp(TRAVEL_GRID_DEG, [0.0, play_deg, play_deg + 3.0], [0.2, 0.2, 0.05])
        n = 4
        return Reversals(np.zeros((n, len(cur))), np.tile(cur, (n, 1)), np.full(n, 0.2),
                         np.full(n, 60.0), np.zeros(n, dtype=np.int64))

    rows = np.arange(4)
    travel, load = compliance._release(reversals(0.5), rows)
    assert travel / load == pytest.approx(3.0 / 0.15, rel=0.02)
    assert compliance._release(reversals(4.0), rows) == pytest.approx((travel, load), rel=0.02)
