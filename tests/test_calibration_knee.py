"""The knee: a backlash end read where the current has stopped moving faster than its scatter
is moved back to where it still does (tsmd/calibration/knee.py, docs/calibration.md session 12)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tsmd.calibration.knee import (
    KNEE_TOLERANCE_DEG,
    branch_scatter,
    knee_index,
    resolvable_end,
)
from tsmd.calibration.options import IdentifyOptions

STEP_DEG = 0.25
GRID = np.arange(0.0, 110.0, STEP_DEG)
SWING_A = 0.14


def _current(scatter_share: float, seed: int = 0) -> np.ndarray:
    """Direction-signed current after a reversal: a steep approach that slows to a creep of
    0.05 % of the swing per deg, plus a fluctuation correlated over about 1 deg (the
    stickslip plant's) of ``scatter_share`` of the swing."""
    rng = np.random.default_rng(seed)
    white = rng.normal(0.0, 1.0, GRID.size + 8)
    wobble = np.convolve(white, np.ones(5) / np.sqrt(5.0), mode="valid")[:GRID.size]
    return SWING_A * (np.tanh(GRID / 6.0) + 0.0005 * GRID + scatter_share * wobble)


def test_an_end_in_the_creep_moves_back_to_where_the_rise_falls_below_the_scatter() -> None:
    yg = _current(0.006)
    scatter = branch_scatter(GRID, yg)
    assert scatter is not None
    # the noise-free approach's rise over the creep, per deg: (swing / 6) sech^2(x / 6)
    rise = SWING_A / 6.0 / np.cosh(GRID / 6.0) ** 2
    expected = GRID[np.flatnonzero(rise < scatter / KNEE_TOLERANCE_DEG)[0]]
    moved = GRID[resolvable_end(GRID, yg, round(35.0 / STEP_DEG))]
    assert abs(moved - expected) <= 2.0


def test_an_end_before_the_knee_is_kept() -> None:
    yg = _current(0.006)
    end = round(8.0 / STEP_DEG)
    assert resolvable_end(GRID, yg, end) == end


def test_without_scatter_the_rules_end_is_kept() -> None:
    yg = _current(0.0)
    end = round(35.0 / STEP_DEG)
    assert resolvable_end(GRID, yg, end) == end


def test_the_knee_comes_earlier_the_larger_the_scatter() -> None:
    small, large = knee_index(GRID, _current(0.002)), knee_index(GRID, _current(0.01))
    assert small is not None and large is not None
    assert large < small


def test_the_scatter_is_measured_on_the_release_branch() -> None:
    quiet = branch_scatter(GRID, _current(0.001))
    noisy = branch_scatter(GRID, _current(0.01))
    assert quiet is not None and noisy is not None
    assert noisy > 5.0 * quiet


def test_a_half_cycle_too_short_for_the_branch_has_no_knee() -> None:
    short = GRID[:round(45.0 / STEP_DEG)]
    yg = _current(0.006)[:short.size]
    assert knee_index(short, yg) is None
    assert resolvable_end(short, yg, 100) == 100


def test_the_knee_is_off_by_default_and_can_be_switched_on() -> None:
    assert not IdentifyOptions().backlash_knee
    assert replace(IdentifyOptions(), backlash_knee=True).backlash_knee
