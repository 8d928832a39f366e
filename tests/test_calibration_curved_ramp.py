"""A loaded ramp that bends smoothly (tsmd.calibration.curved_ramp) is read at its start, not at
a knee's corner; a real corner still is a knee."""

from __future__ import annotations

import numpy as np
import pytest
from support.branch_currents import knob_grid, noisy, steep_then_loaded_current, wall_current

from tsmd.calibration.branch_fit import fit_edge
from tsmd.calibration.curved_ramp import curved_hinge

NOISE_A = 0.001


@pytest.mark.parametrize("bend_deg", [6.0, 12.0])
def test_a_smoothly_flattening_ramp_gives_the_edge_where_the_current_leaves_the_level(
        bend_deg: float) -> None:
    x = knob_grid()
    fit = fit_edge(x, noisy(wall_current(x, engage_deg=15.0, bend_deg=bend_deg), NOISE_A,
                            seed=5), NOISE_A)
    assert fit is not None and fit.kind != "knee"
    assert abs(fit.edge_deg - 15.0) < 1.0


def test_a_corner_between_steep_and_loaded_rise_is_still_a_knee_against_the_curve() -> None:
    x = knob_grid()
    y = noisy(steep_then_loaded_current(x, engage_deg=16.0, release_deg=22.0), NOISE_A, seed=6)
    fit = fit_edge(x, y, NOISE_A)
    assert fit is not None and fit.kind == "knee"
    assert abs(fit.edge_deg - 22.0) < 1.0


def test_a_ramp_that_bends_upwards_is_no_curved_hinge() -> None:
    x = knob_grid()
    rss, _ = curved_hinge(x, 0.03 + 1e-4 * np.maximum(x - 15.0, 0.0) ** 2, np.array([15.0]))
    assert not np.isfinite(rss[0])
