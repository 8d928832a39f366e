"""With the product's curved-hinge check (tsmd.calibration.curved_ramp), a loaded ramp that bends
smoothly is read at its start, not at a knee's corner; a real corner still is a knee; without
the check (the default) nothing changes."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from support.branch_currents import knob_grid, noisy, steep_then_loaded_current, wall_current

from tsmd.calibration.branch_fit import fit_edge
from tsmd.calibration.curved_ramp import curved_hinge
from tsmd.calibration.options import device_options
from tsmd.profile.files import load_device_model

NOISE_A = 0.001
JAWCRIMP_SHEET = Path(__file__).parents[1] / "profiles/devices/family/jawcrimp.yaml"


@pytest.mark.parametrize("bend_deg", [6.0, 12.0])
def test_a_smoothly_flattening_ramp_gives_the_edge_where_the_current_leaves_the_level(
        bend_deg: float) -> None:
    x = knob_grid()
    fit = fit_edge(x, noisy(wall_current(x, engage_deg=15.0, bend_deg=bend_deg), NOISE_A,
                            seed=5), NOISE_A, curve_check=True)
    assert fit is not None and fit.kind != "knee"
    assert abs(fit.edge_deg - 15.0) < 1.0


def test_a_corner_between_steep_and_loaded_rise_is_still_a_knee_against_the_curve() -> None:
    x = knob_grid()
    y = noisy(steep_then_loaded_current(x, engage_deg=16.0, release_deg=22.0), NOISE_A, seed=6)
    fit = fit_edge(x, y, NOISE_A, curve_check=True)
    assert fit is not None and fit.kind == "knee"
    assert abs(fit.edge_deg - 22.0) < 1.0


def test_without_the_check_the_smooth_ramp_still_reads_as_before() -> None:
    x = knob_grid()
    y = noisy(wall_current(x, engage_deg=15.0, bend_deg=8.0), NOISE_A, seed=5)
    assert fit_edge(x, y, NOISE_A) == fit_edge(x, y, NOISE_A, curve_check=False)
    fit = fit_edge(x, y, NOISE_A)
    assert fit is not None and fit.kind != "curved"


def test_the_sheets_edge_curve_turns_the_check_on_for_that_knob_only() -> None:
    device = load_device_model(JAWCRIMP_SHEET)
    knobs = (replace(device.knobs[0], edge_curve=True), replace(device.knobs[1], edge_curve=None))
    phi1, phi2 = device_options(None, replace(device, knobs=knobs))
    assert phi1.edge_curve and not phi2.edge_curve


def test_a_ramp_that_bends_upwards_is_no_curved_hinge() -> None:
    x = knob_grid()
    rss, _ = curved_hinge(x, 0.03 + 1e-4 * np.maximum(x - 15.0, 0.0) ** 2, np.array([15.0]))
    assert not np.isfinite(rss[0])
