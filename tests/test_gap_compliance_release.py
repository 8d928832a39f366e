"""The compliance sheet's figure when a light load's lost motion carries a gear's play."""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import pytest

from tsmd.gap import compliance
from tsmd.gap.crosstest import make_session
from tsmd.gap.data import GapSeries, series_from_recording
from tsmd.gap.presets import PRESETS
from tsmd.gap.reversal import TRAVEL_GRID_DEG, Reversals, _after, _reversal_pairs

RATE_HZ = 50.0
PLAY_DEG = 5.0
"""A geared handle's play crossed before the tip returns from the light load only (warmgear:
4.3 deg of knob, more than its lost motion grows from 40 to 60 deg)."""


@functools.cache
def _series(unit: int, case: str = "none") -> tuple[GapSeries, ...]:
    recs = make_session(PRESETS["capstan"], case, 4.0, RATE_HZ, unit,
                        unit_variation=0.0 if unit == 0 else 0.1)
    return tuple(series_from_recording(r, f"{case}-{unit}-{i}")
                 for i, r in enumerate(recs) if "segments" in r.metadata)


def _play_at_light_load(series: tuple[GapSeries, ...]) -> list[GapSeries]:
    """Knob 1's tip returns from its + side's 40 deg reversals only after the knob has crossed
    :data:`PLAY_DEG` more (the drum held by its friction while the pinion crosses the play);
    the delay fades out between 20 and 30 deg of travel, before the next reversal."""
    out = []
    for s in series:
        x, tip = s.knob_deg[:, 0], s.tip_deg.copy()
        for a, b in _reversal_pairs(x):
            if abs(x[a] - 40.0) > compliance.LEVEL_BAND_DEG:
                continue
            travel, end = _after(x, a, b)
            delay = PLAY_DEG * np.clip((30.0 - travel) / 10.0, 0.0, 1.0)
            tip[a:end, 0] = np.interp(travel - delay, travel, s.tip_deg[a:end, 0])
        out.append(dataclasses.replace(s, tip_deg=tip))
    return out


def _units(with_play: bool) -> list[list[GapSeries]]:
    five = _play_at_light_load(_series(5)) if with_play else list(_series(5))
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
