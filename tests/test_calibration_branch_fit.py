"""The least-squares dead-zone edge (tsmd.calibration.branch_fit) on synthetic tendon currents."""

from __future__ import annotations

import numpy as np
from support.branch_currents import knob_grid, noisy, steep_then_loaded_current, toe_current

from tsmd.calibration.branch_fit import KNEE_CHUNK, _knee, fit_edge
from tsmd.calibration.estimate import estimate
from tsmd.calibration.signal import remove_spikes

NOISE_A = 0.001


def test_a_toe_gives_the_edge_where_its_linear_part_meets_the_dead_zone_level() -> None:
    x = knob_grid()
    y = noisy(toe_current(x, engage_deg=15.0, toe_deg=6.0), NOISE_A, seed=1)
    fit = fit_edge(x, y, NOISE_A)
    assert fit is not None and fit.kind == "hinge"
    assert abs(fit.edge_deg - 18.0) < 1.0


def test_the_toe_edge_moves_with_the_toe_not_with_where_the_current_starts_rising() -> None:
    x = knob_grid()
    short = fit_edge(x, toe_current(x, engage_deg=15.0, toe_deg=2.0), NOISE_A)
    long = fit_edge(x, toe_current(x, engage_deg=15.0, toe_deg=10.0), NOISE_A)
    assert short is not None and long is not None
    assert abs((long.edge_deg - short.edge_deg) - 4.0) < 1.0


def test_a_steep_first_rise_gives_the_edge_where_it_turns_into_the_loaded_ramp() -> None:
    x = knob_grid()
    y = noisy(steep_then_loaded_current(x, engage_deg=16.0, release_deg=20.0), NOISE_A, seed=2)
    fit = fit_edge(x, y, NOISE_A)
    assert fit is not None and fit.kind == "knee"
    assert abs(fit.edge_deg - 20.0) < 1.0


def test_a_gentle_first_rise_is_no_knee() -> None:
    x = knob_grid()
    y = steep_then_loaded_current(x, engage_deg=16.0, release_deg=20.0,
                                  steep_A_per_deg=0.0025, loaded_A_per_deg=0.002)
    fit = fit_edge(x, noisy(y, NOISE_A, seed=3), NOISE_A)
    assert fit is not None and fit.kind == "hinge"


def test_spikes_removed_by_the_conditioning_do_not_move_the_edge() -> None:
    x = knob_grid()
    clean = toe_current(x, engage_deg=15.0, toe_deg=6.0)
    spiky, n = remove_spikes(noisy(clean, NOISE_A, seed=4, spikes=6))
    assert n >= 6
    plain = fit_edge(x, noisy(clean, NOISE_A, seed=4), NOISE_A)
    fit = fit_edge(x, spiky, NOISE_A)
    assert fit is not None and plain is not None
    assert abs(fit.edge_deg - plain.edge_deg) < 0.5


def test_a_current_that_only_falls_has_no_edge() -> None:
    x = knob_grid()
    assert fit_edge(x, 0.03 - 0.0005 * x, NOISE_A) is None


def test_the_uncertainty_of_the_edge_grows_with_the_noise() -> None:
    x = knob_grid()
    y = toe_current(x, engage_deg=15.0, toe_deg=6.0)

    def u95(sigma_A: float) -> float:
        edges = []
        for seed in range(8):
            fit = fit_edge(x, noisy(y, sigma_A, seed=100 + seed), sigma_A)
            assert fit is not None
            edges.append(fit.edge_deg)
        return estimate(edges, float("nan")).u95_deg

    assert u95(0.006) > 2.0 * u95(0.0005)


def test_every_knee_candidate_is_a_least_squares_fit_across_chunks() -> None:
    rng = np.random.default_rng(3)
    x = np.linspace(0.0, 30.0, 200)
    y = 0.02 * np.maximum(x - 8.0, 0.0) + rng.normal(0.0, 0.01, x.size)
    e1 = np.linspace(1.0, 20.0, 2 * KNEE_CHUNK + 7)
    e2 = e1 + 4.0
    rss, coef = _knee(x, y, e1, e2)
    for k in (0, KNEE_CHUNK, e1.size - 1):
        basis = np.column_stack([np.ones_like(x), np.maximum(x - e1[k], 0.0),
                                 np.maximum(x - e2[k], 0.0)])
        want, res, *_ = np.linalg.lstsq(basis, y, rcond=None)
        np.testing.assert_allclose(coef[k], want, rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(rss[k], res[0], rtol=1e-6)
