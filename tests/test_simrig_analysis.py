"""Dead zone and backlash measured from the tip angle of a sweep (ground truth definitions)."""

from __future__ import annotations

import numpy as np
import pytest

from simrig.analysis import (
    SweepAnalysisError,
    loaded_slope,
    measure_by_lines,
    measure_dead_zone_backlash,
    split_passes,
)

SLOPE = 1.3


def play_dead_zone_sweep(
    play_pos_deg: float, play_neg_deg: float, dead_pos_deg: float, dead_neg_deg: float
) -> tuple[np.ndarray, np.ndarray]:
    """A textbook loop: a play (backlash) operator followed by a dead zone, 2 cycles +-90 deg.

    Rising, the play output is ``q - play_neg``; falling it is ``q + play_pos`` (half-widths
    may differ). The dead zone spans ``[-dead_neg, dead_pos]`` of the play output.
    """
    t = np.arange(0.0, 50.0, 0.004)
    q = 90.0 * np.sin(2.0 * np.pi * 0.04 * t)
    x = np.empty_like(q)
    x[0] = 0.0
    for i in range(1, q.size):
        x[i] = min(max(x[i - 1], q[i] - play_neg_deg), q[i] + play_pos_deg)
    tip = SLOPE * (np.maximum(x - dead_pos_deg, 0.0) + np.minimum(x + dead_neg_deg, 0.0))
    return q, tip


def test_passes_start_and_end_at_reversals() -> None:
    q = np.r_[np.linspace(0, 90, 10), np.linspace(85, -90, 30), np.linspace(-85, 90, 30), 80.0]
    passes = split_passes(q)
    assert [p[2] for p in passes] == [-1, 1]
    assert q[passes[0][0]] == 90.0
    assert q[passes[1][0]] == -90.0


def test_textbook_loop_gives_its_dead_zone_and_backlash() -> None:
    q, tip = play_dead_zone_sweep(8.0, 10.0, 12.0, 6.0)
    m = measure_dead_zone_backlash(q, tip, threshold_deg=0.01)
    # Rising the play output is q - 10: the tip leaves the plateau at q = 12 + 10.
    assert m.dead_zone_pos_deg == pytest.approx(22.0, abs=0.1)
    # Falling it is q + 8: the tip leaves the plateau at q = -6 - 8.
    assert m.dead_zone_neg_deg == pytest.approx(-14.0, abs=0.1)
    # After a reversal the play takes its full width before the output moves.
    assert m.backlash_pos_deg == pytest.approx(18.0, abs=0.1)
    assert m.backlash_neg_deg == pytest.approx(18.0, abs=0.1)


def test_threshold_adds_its_tip_travel_over_the_slope() -> None:
    q, tip = play_dead_zone_sweep(8.0, 8.0, 12.0, 12.0)
    m = measure_dead_zone_backlash(q, tip, threshold_deg=1.3)
    assert m.dead_zone_pos_deg == pytest.approx(20.0 + 1.0, abs=0.1)
    assert m.backlash_pos_deg == pytest.approx(16.0 + 1.0, abs=0.1)


def test_measures_survive_tracker_noise() -> None:
    q, tip = play_dead_zone_sweep(8.0, 8.0, 12.0, 12.0)
    noisy = tip + np.random.default_rng(0).normal(0.0, 0.1, tip.size)
    m = measure_dead_zone_backlash(q, noisy, threshold_deg=1.0)
    exact = measure_dead_zone_backlash(q, tip, threshold_deg=1.0)
    assert np.allclose(m, exact, atol=0.7)


def test_loaded_slope_of_the_textbook_loop() -> None:
    q, tip = play_dead_zone_sweep(8.0, 8.0, 12.0, 12.0)
    assert loaded_slope(q, tip, 40.0, 85.0) == pytest.approx((SLOPE, SLOPE))


def test_without_a_complete_pass_each_way_it_refuses() -> None:
    q = np.linspace(-90.0, 90.0, 100)
    with pytest.raises(SweepAnalysisError, match="complete rising and one falling"):
        measure_dead_zone_backlash(q, q)


@pytest.mark.parametrize(
    ("knob", "tip", "threshold", "message"),
    [
        (np.zeros(5), np.zeros(4), 1.0, "one length"),
        (np.zeros(5), np.zeros(5), 0.0, "threshold_deg"),
        (np.r_[np.zeros(4), np.nan], np.zeros(5), 1.0, "finite"),
    ],
)
def test_bad_input_is_refused_clearly(
    knob: np.ndarray, tip: np.ndarray, threshold: float, message: str
) -> None:
    with pytest.raises(SweepAnalysisError, match=message):
        measure_dead_zone_backlash(knob, tip, threshold_deg=threshold)


def paper_lines_sweep(backlash_deg: float, dead_deg: float, release: float, loaded: float,
                      plateau_creep_deg: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Two +-90 deg cycles whose passes are the paper's lines, symmetric in the two directions:
    held for ``backlash_deg``, a release line of slope ``release`` down to a plateau that ends at
    ``+-dead_deg``, across which the tip creeps by ``plateau_creep_deg``, then the loaded line."""
    top = loaded * (90.0 - dead_deg)
    plateau_start = 90.0 - backlash_deg - top / release  # knob where the release reaches 0

    def rising(q: np.ndarray) -> np.ndarray:  # from the reversal at -90 (mirror of falling)
        return -falling(-q)

    def falling(q: np.ndarray) -> np.ndarray:
        creep = plateau_creep_deg * (plateau_start - q) / (plateau_start + dead_deg)
        return np.select(
            [q >= 90.0 - backlash_deg, q >= plateau_start, q >= -dead_deg],
            [np.full_like(q, top), top - release * (90.0 - backlash_deg - q), -creep],
            -plateau_creep_deg + (top - plateau_creep_deg) / (90.0 - dead_deg) * (q + dead_deg))

    down, up = np.linspace(90.0, -90.0, 3600), np.linspace(-90.0, 90.0, 3600)
    q = np.r_[np.linspace(0.0, 90.0, 900)[:-1], down, up[1:], down[1:], up[1:]]
    y = np.r_[np.linspace(0.0, top, 900)[:-1], falling(down), rising(up[1:]),
              falling(down[1:]), rising(up[1:])]
    return q, y


def test_lines_read_the_corners_of_the_paper_lines_where_release_and_load_differ() -> None:
    q, tip = paper_lines_sweep(backlash_deg=16.0, dead_deg=18.0, release=1.6, loaded=1.1)
    m = measure_by_lines(q, tip)
    assert m.dead_zone_pos_deg == pytest.approx(18.0, abs=0.3)
    assert m.dead_zone_neg_deg == pytest.approx(-18.0, abs=0.3)
    assert m.backlash_pos_deg == pytest.approx(16.0, abs=0.3)
    assert m.backlash_neg_deg == pytest.approx(16.0, abs=0.3)


def test_a_tip_creeping_along_the_plateau_is_read_where_it_leaves_the_plateau() -> None:
    # 2.5 deg of creep over a ~50 deg plateau (0.05 deg/deg): against the plateau's median
    # level the 1 deg threshold fired > 3 deg early; against its line it fires where the tip
    # has risen 1 deg off the plateau's line (1 / 1.1 deg of knob past the corner).
    q, tip = paper_lines_sweep(backlash_deg=16.0, dead_deg=18.0, release=1.6, loaded=1.1,
                               plateau_creep_deg=2.5)
    by_threshold = measure_dead_zone_backlash(q, tip, threshold_deg=1.0)
    assert by_threshold.dead_zone_pos_deg == pytest.approx(18.0 + 1.0 / 1.1, abs=0.3)
    assert by_threshold.dead_zone_neg_deg == pytest.approx(-18.0 - 1.0 / 1.1, abs=0.3)


def creeping_plateau_sweep(creep_deg_per_deg: float, dead_deg: float = 12.0,
                           slope: float = 1.35) -> tuple[np.ndarray, np.ndarray]:
    """Two +-90 deg cycles, symmetric: the release line down to a plateau along which the tip
    creeps at ``creep_deg_per_deg`` (tip per knob degree), the loaded line from ``dead_deg``."""
    up = np.linspace(-90.0, 90.0, 4501)
    plateau = -14.0 + creep_deg_per_deg * up
    loaded = -14.0 + creep_deg_per_deg * dead_deg + slope * (up - dead_deg)
    release = -loaded[-1] + slope * np.maximum(0.0, up + 74.0)
    y_up = np.maximum(np.minimum(release, plateau), loaded)
    return (np.r_[up, -up[1:], up[1:], -up[1:]], np.r_[y_up, -y_up[1:], y_up[1:], -y_up[1:]])


@pytest.mark.parametrize("creep", [0.03, 0.07, 0.1, -0.03])
def test_the_edge_of_a_creeping_plateau_does_not_move_with_its_creep(creep: float) -> None:
    q, tip = creeping_plateau_sweep(creep)
    still = measure_dead_zone_backlash(*creeping_plateau_sweep(0.0))
    m = measure_dead_zone_backlash(q, tip)
    assert m.dead_zone_pos_deg == pytest.approx(still.dead_zone_pos_deg, abs=0.15)
    assert m.dead_zone_neg_deg == pytest.approx(still.dead_zone_neg_deg, abs=0.15)


def test_a_still_plateau_is_read_at_its_level_plus_the_threshold() -> None:
    m = measure_dead_zone_backlash(*creeping_plateau_sweep(0.0))
    assert m.dead_zone_pos_deg == pytest.approx(12.0 + 1.0 / 1.35, abs=0.05)
    assert m.dead_zone_neg_deg == pytest.approx(-12.0 - 1.0 / 1.35, abs=0.05)


def test_a_creeping_plateau_survives_tracker_noise() -> None:
    q, tip = creeping_plateau_sweep(0.07)
    noisy = tip + np.random.default_rng(1).normal(0.0, 0.2, tip.size)
    m = measure_dead_zone_backlash(q, noisy)
    assert m.dead_zone_pos_deg == pytest.approx(12.0 + 1.0 / 1.35, abs=0.5)
    assert m.dead_zone_neg_deg == pytest.approx(-12.0 - 1.0 / 1.35, abs=0.5)


@pytest.mark.parametrize("creep", [0.0, 0.05])
def test_a_tip_that_never_leaves_its_plateau_has_no_dead_zone_edge(creep: float) -> None:
    up = np.linspace(-90.0, 90.0, 4501)
    y_up = np.minimum(1.35 * (up + 60.0), creep * (up + 60.0))
    q, tip = np.r_[up, -up[1:], up[1:], -up[1:]], np.r_[y_up, -y_up[1:], y_up[1:], -y_up[1:]]
    m = measure_dead_zone_backlash(q, tip)
    assert np.isnan(m.dead_zone_pos_deg) and np.isnan(m.dead_zone_neg_deg)


def test_lines_give_nan_where_the_tip_shows_no_plateau() -> None:
    q = 90.0 * np.sin(np.linspace(0.0, 4.0 * np.pi, 4000))
    m = measure_by_lines(q, 1.2 * q)
    assert np.isnan(m.dead_zone_pos_deg) and np.isnan(m.backlash_pos_deg)


def test_lines_refuse_the_inputs_the_threshold_reading_refuses() -> None:
    with pytest.raises(SweepAnalysisError, match="finite"):
        measure_by_lines(np.array([0.0, 1.0, np.nan]), np.zeros(3))
