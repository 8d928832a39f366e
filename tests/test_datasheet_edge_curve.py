"""The data sheet chooses the curved-hinge check per knob on its own unit
(tsmd.datasheet_edge_curve, session 21): on where it makes the current's edges scatter less
about the tip's by more than that change's own sampling error, off where it changes nothing or
scatters more."""

from __future__ import annotations

import math

import numpy as np
from support.branch_currents import wall_current
from support.profiles import DEVICE

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.identify import identify_sweep
from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.run import device_options
from tsmd.datasheet_edge_curve import EdgeRead, edge_curve_scores, edge_pairs, with_edge_curve
from tsmd.profile import load_device_model

PERIOD_S = 0.004
ENGAGE_DEG = 20.0


def wall_sweep_point(seed: int = 0) -> GridPoint:
    """Two and a half +-90 deg cycles of a knob whose loaded current bends smoothly past the
    engagement at +-ENGAGE_DEG (a tip pressed into a wall), identified without the check."""
    t = np.arange(0.0, 2.5 / 0.06, PERIOD_S)
    q = 90.0 * np.sin(2 * math.pi * 0.06 * t - math.pi / 2)
    direction = np.where(np.gradient(q, PERIOD_S) >= 0, 1.0, -1.0)
    ramp = np.where(direction > 0, wall_current(q, ENGAGE_DEG, level_A=0.0, bend_deg=10.0),
                    -wall_current(-q, ENGAGE_DEG, level_A=0.0, bend_deg=10.0))
    current = 0.02 * direction + ramp + np.random.default_rng(seed).normal(0.0, 0.003, t.size)
    return GridPoint(0, 0.0, identify_sweep(t, q, q, current, IdentifyOptions()))


def tip_truth_at_engagement() -> dict[tuple[int, float], dict[str, float]]:
    return {(0, 0.0): {"dead_zone_pos_deg": ENGAGE_DEG, "dead_zone_neg_deg": -ENGAGE_DEG}}


def test_the_check_re_reads_a_smooth_wall_ramps_edges_nearer_the_tip() -> None:
    options = (IdentifyOptions(), IdentifyOptions())
    reads = edge_pairs([wall_sweep_point()], options, tip_truth_at_engagement())
    assert len(reads) >= 4
    assert max(abs(r[3]) for r in reads) > 5.0
    assert max(abs(r[4]) for r in reads) < 2.0


def reads_at_one_point(off_deg: list[float], on_deg: list[float], knob: int = 0
                       ) -> list[EdgeRead]:
    return [(knob, 0.0, "dead_zone_pos_deg", a, b) for a, b in zip(off_deg, on_deg, strict=True)]


def test_a_knob_whose_edges_flip_without_the_check_takes_it() -> None:
    off = [10.0 if i % 2 else -1.0 for i in range(24)]
    on = [-1.0 + 0.1 * (i % 3) for i in range(24)]
    phi1, _ = edge_curve_scores(reads_at_one_point(off, on))
    assert phi1.chosen and phi1.gain_deg > 4.0


def test_a_check_that_changes_no_edge_stays_off() -> None:
    off = [0.5 + 0.1 * i for i in range(24)]
    _, phi2 = edge_curve_scores(reads_at_one_point(off, off, knob=1))
    assert phi2.changed == 0 and not phi2.chosen


def test_a_check_that_scatters_the_edges_more_stays_off() -> None:
    off = [0.5 + 0.1 * (i % 2) for i in range(24)]
    on = [-3.0 if i % 2 else 1.0 for i in range(24)]
    phi1, _ = edge_curve_scores(reads_at_one_point(off, on))
    assert phi1.gain_deg < 0 and not phi1.chosen


def test_a_steady_shift_alone_does_not_choose_the_check() -> None:
    """A constant shift of every edge is what the product's reading offset takes out."""
    off = [3.0 + 0.2 * (i % 4) for i in range(24)]
    on = [v - 2.5 for v in off]
    phi1, _ = edge_curve_scores(reads_at_one_point(off, on))
    assert phi1.mean_abs_on_deg < phi1.mean_abs_off_deg and not phi1.chosen


def test_a_few_small_gains_within_their_scatter_leave_the_check_off() -> None:
    off = [1.0 + 0.2 * (i % 2) for i in range(24)]
    on = [v - (0.3 if i == 0 else 0.0) for i, v in enumerate(off)]
    phi1, _ = edge_curve_scores(reads_at_one_point(off, on))
    assert phi1.changed == 1 and not phi1.chosen


def test_the_choice_is_written_per_knob_and_off_is_absent() -> None:
    device = with_edge_curve(load_device_model(DEVICE), (True, False))
    assert (device.knobs[0].edge_curve, device.knobs[1].edge_curve) == (True, None)
    phi1, phi2 = device_options(None, device)
    assert phi1.edge_curve and not phi2.edge_curve
