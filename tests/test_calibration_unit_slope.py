"""The unit's loaded slope: readings of the backlash gain weighed by their scatter."""

from __future__ import annotations

import math

import pytest

from tsmd.calibration.unit_slope import (
    PRODUCT_SLOPE_SCATTER,
    GainReading,
    gain_scatter,
    weighed_omega,
)


def test_without_readings_omega_is_the_sheets() -> None:
    assert weighed_omega(1.4, []) == 1.4


def test_a_reading_whose_sides_agree_sets_the_units_slope() -> None:
    tight = GainReading(0.3, 0.2, 0.0)
    assert weighed_omega(1.4, [tight]) == pytest.approx(1.4 * 0.8 / 0.7, rel=0.002)


def test_a_reading_whose_sides_disagree_leaves_the_sheets_slope() -> None:
    loose = GainReading(0.3, 0.2, 1.0)
    assert weighed_omega(1.4, [loose]) == pytest.approx(1.4, rel=0.002)


def test_of_two_readings_the_one_with_less_scatter_wins() -> None:
    settle = GainReading(0.27, 0.36, 0.06)  # coilpipe 103 phi2-like: one side jumps
    rule = GainReading(0.23, 0.22, 0.006)
    w = weighed_omega(1.26, [settle, rule])
    assert w == pytest.approx(1.26 * rule.ratio(), rel=0.01)
    assert abs(w - 1.26 * rule.ratio()) < abs(w - 1.26 * settle.ratio())


def test_equal_readings_and_a_large_prior_give_the_readings_mean() -> None:
    a, b = GainReading(0.3, 0.25, 0.02), GainReading(0.3, 0.35, 0.02)
    w = weighed_omega(1.0, [a, b])
    mean = 0.5 * (a.ratio() + b.ratio())
    prior_weight = (0.02 / 0.7) ** 2 / PRODUCT_SLOPE_SCATTER**2
    assert w == pytest.approx(mean, abs=prior_weight)


def test_scatter_is_the_disagreement_of_the_sides_not_the_trend_over_the_grid() -> None:
    assert gain_scatter([0.2, 0.3, 0.4], [0.2, 0.3, 0.4]) == 0.0
    assert gain_scatter([0.2, 0.2], [0.3, 0.1]) == pytest.approx(0.1 / math.sqrt(2))


def test_a_reading_without_finite_pairs_has_no_weight() -> None:
    assert gain_scatter([math.nan], [0.3]) == math.inf
    assert weighed_omega(1.4, [GainReading(0.3, 0.2, math.inf)]) == pytest.approx(1.4)


def test_the_weighed_slope_stays_within_the_plausible_slopes() -> None:
    assert weighed_omega(4.9, [GainReading(0.79, 0.0, 0.0)]) == 5.0


def test_a_product_whose_slope_does_not_follow_the_gain_keeps_the_sheets_slope() -> None:
    tight = GainReading(0.3, 0.2, 0.0)
    assert weighed_omega(1.4, [tight], gain_weight=0.0) == pytest.approx(1.4)


def test_the_sheets_weight_takes_that_share_of_the_readings_move() -> None:
    tight = GainReading(0.3, 0.2, 0.0)
    full = weighed_omega(1.4, [tight])
    assert weighed_omega(1.4, [tight], gain_weight=0.25) == pytest.approx(
        1.4 + 0.25 * (full - 1.4), rel=1e-9)


def test_without_a_weight_the_unit_takes_the_whole_move() -> None:
    tight = GainReading(0.3, 0.2, 0.0)
    assert weighed_omega(1.4, [tight], gain_weight=None) == weighed_omega(1.4, [tight])
