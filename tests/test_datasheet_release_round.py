"""The product's rounded release fitted on the sheet's unit (tsmd.datasheet_release_round)."""

from __future__ import annotations

import numpy as np
import pytest

from tsmd.calibration.identify import split_half_cycles
from tsmd.compensation.release_round import reference_backlash_deg
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.datasheet_release_round import fit_release_round, release_drop_deg, worth_a_field

RATE_HZ = 50.0


def tension(beta: float = 0.1, x0_pos: float = -40.0, x0_neg: float = 40.0,
            omega: float = 1.3) -> TensionPlayParams:
    grid = (-90.0, 0.0, 90.0)
    return TensionPlayParams(omega, 0.0, 0.0, grid, (20.0,) * 3, (-20.0,) * 3, (beta,) * 3,
                             (beta,) * 3, (x0_pos,) * 3, (x0_neg,) * 3)


def sweep_with_tip(p: TensionPlayParams, shift: float, rnd: float) -> tuple[np.ndarray,
                                                                            np.ndarray]:
    """A +-90 deg sweep whose tip falls after each reversal as the rounded model says."""
    t = np.arange(0.0, 75.0, 1.0 / RATE_HZ)
    x = -90.0 * np.cos(2 * np.pi * 0.04 * t)
    tip = np.zeros_like(x)
    slope = p.omega / (1.0 - p.backlash_gain_pos[1])
    for direction, a, b, _ in split_half_cycles(x, 10.0):
        side = -direction
        x0 = p.zero_load_pos_deg[1] if side > 0 else p.zero_load_neg_deg[1]
        backlash = abs(p.backlash_gain_pos[1] * (x[a] - x0))
        b_ref = reference_backlash_deg(p.backlash_gain_pos[1], x0, side)
        start = tip[a - 1] if a > 0 else 0.0
        tip[a:b] = start - side * release_drop_deg(side * (x[a] - x[a:b]),
                                                   backlash + shift * b_ref, rnd * b_ref, slope)
    return x, tip


def test_the_fit_finds_the_shape_the_tip_falls_with() -> None:
    p = tension()
    x, tip = sweep_with_tip(p, 0.25, 0.6)
    fit = fit_release_round(x, tip, RATE_HZ, p)
    assert fit is not None
    assert fit[0] == pytest.approx(0.25, abs=0.051)
    assert fit[1] == pytest.approx(0.6, abs=0.051)
    assert fit[3] < fit[2]


def test_a_sharp_tip_keeps_the_sharp_corner() -> None:
    p = tension()
    x, tip = sweep_with_tip(p, 0.0, 0.0)
    fit = fit_release_round(x, tip, RATE_HZ, p)
    assert fit is not None
    assert fit[0] == 0.0
    assert not worth_a_field(fit)


def test_a_sweep_without_reversals_has_no_fit() -> None:
    x = np.linspace(-90.0, 90.0, 2000)
    assert fit_release_round(x, 0.5 * x, RATE_HZ, tension()) is None
