"""The dead zone ends at the current's first sustained rise out of the slack level: a tooth's
flat stretch on the loaded branch is not read as the dead zone, and a release step followed by
a long level is not read as its end (session 20)."""

from __future__ import annotations

import numpy as np

from tsmd.calibration.identify import IdentifyOptions
from tsmd.calibration.slack_rise import before_sustained_rise

OPTS = IdentifyOptions()
STEP = OPTS.grid_step_deg


def _current(spans: list[tuple[float, float]]) -> tuple[list[tuple[int, int]], list[bool],
                                                        np.ndarray]:
    """Pieces, their flatness and the current on the grid: each span (length in deg, slope in
    A/deg) continuing from the last level; a span is flat when its slope is below 0.3 mA/deg."""
    yg: list[float] = []
    pieces, flat = [], []
    level = 0.02
    for length_deg, slope in spans:
        n = round(length_deg / STEP)
        pieces.append((len(yg), len(yg) + n))
        flat.append(slope < 3e-4)
        yg.extend(level + slope * STEP * np.arange(1, n + 1))
        level = yg[-1]
    return pieces, flat, np.asarray(yg)


def test_a_tooth_flat_after_a_sustained_rise_is_not_the_dead_zone() -> None:
    # slack 40 deg, the load rising 12 deg more steeply than the loaded ramp (warmgear: 1.1-1.5
    # times), a 4-deg tooth flat, rising on
    pieces, flat, yg = _current([(40.0, 0.0), (12.0, 4e-3), (4.0, 0.0), (30.0, 3e-3)])
    assert before_sustained_rise(pieces, flat, STEP, OPTS, yg, pieces[2]) == pieces[0]


def test_a_release_step_followed_by_a_long_level_is_not_the_rise() -> None:
    # release level, a 9-deg step at the loaded slope, the dead zone's level 40 deg, the load
    pieces, flat, yg = _current([(20.0, 0.0), (9.0, 3e-3), (40.0, 0.0), (30.0, 3e-3)])
    assert before_sustained_rise(pieces, flat, STEP, OPTS, yg, pieces[2]) == pieces[2]


def test_a_short_steep_step_between_slack_levels_is_not_the_rise() -> None:
    # where the tip re-enters the dead zone the released tendon drops its last tension: 3 deg
    pieces, flat, yg = _current([(30.0, 0.0), (3.0, 6e-3), (2.5, 0.0), (30.0, 3e-3)])
    assert before_sustained_rise(pieces, flat, STEP, OPTS, yg, pieces[2]) == pieces[2]


def test_a_gentle_rise_between_slack_levels_is_not_the_rise() -> None:
    # the release branch climbing at a third of the loaded slope for 20 deg
    pieces, flat, yg = _current([(30.0, 0.0), (20.0, 1e-3), (10.0, 0.0), (30.0, 3e-3)])
    assert before_sustained_rise(pieces, flat, STEP, OPTS, yg, pieces[2]) == pieces[2]


def test_a_rise_a_little_less_steep_than_the_loaded_average_is_the_rise() -> None:
    # the loaded branch from the edge to the first tooth flat measures 0.97-1.09 times the last
    # quarter's slope on warmgear (session 22); here 0.95 times: still the load, not a release
    pieces, flat, yg = _current([(40.0, 0.0), (30.0, 2.85e-3), (8.0, 0.0), (30.0, 3e-3)])
    assert before_sustained_rise(pieces, flat, STEP, OPTS, yg, pieces[2]) == pieces[0]


def test_a_release_rise_at_half_the_loaded_slope_is_not_the_rise() -> None:
    # the release branch's long rises reach at most 0.42 of the loaded slope (warmgear)
    pieces, flat, yg = _current([(30.0, 0.0), (12.0, 1.5e-3), (8.0, 0.0), (30.0, 3e-3)])
    assert before_sustained_rise(pieces, flat, STEP, OPTS, yg, pieces[2]) == pieces[2]
