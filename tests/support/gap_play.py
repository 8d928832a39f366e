"""A geared handle's play crossed before the tip returns from the light load only (warmgear,
docs/gap.md "Session 19"), put into a unit's protocol series: shared by the compliance tests."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable

import numpy as np

from tsmd.gap import compliance
from tsmd.gap.data import GapSeries
from tsmd.gap.reversal import _after, _reversal_pairs

PLAY_DEG = 5.0
"""A geared handle's play crossed before the tip returns from the light load only (warmgear:
4.3 deg of knob, more than its lost motion grows from 40 to 60 deg)."""


def play_at_light_load(series: Iterable[GapSeries]) -> list[GapSeries]:
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
