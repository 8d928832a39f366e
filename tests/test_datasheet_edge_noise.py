"""The sheet's reading offset leaves out dead-zone edges that the tracker's noise alone moves."""

from __future__ import annotations

import math

import numpy as np

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.sweep_result import SweepResult
from tsmd.datasheet_offset import noise_bound_edges, offset_readings
from tsmd.recording import Recording
from tsmd.tip_truth import tip_truth

RATE_HZ = 100.0
EDGE_DEG = 20.0
TRACKER_NOISE_DEG = 0.2


def _point(creep_per_deg: float, exit_slope: float = 1.0) -> GridPoint:
    """Knob 0 swept +-90 deg (3 cycles); the tip has no hysteresis and a dead zone of
    +-``EDGE_DEG`` along which it creeps ``creep_per_deg`` tip deg per knob deg; past the edge
    it leaves at ``exit_slope`` tip deg per knob deg for 30 deg, then at 1."""
    t = np.arange(0.0, 60.0, 1.0 / RATE_HZ)
    q = -90.0 * np.cos(2.0 * math.pi * 0.05 * t)
    past = np.abs(q) - EDGE_DEG
    leaving = np.where(past < 30.0, exit_slope * past, 30.0 * exit_slope + past - 30.0)
    tip = np.where(past > 0.0, np.sign(q) * (EDGE_DEG * creep_per_deg + leaving),
                   creep_per_deg * q)
    rec = Recording({"t": t, "cmd1": q, "pos1": q, "tip1": tip, "cmd2": 0.0 * t,
                     "pos2": 0.0 * t, "tip2": 0.0 * t},
                    {"calibration_sweep_start_s": "1.0"})
    return GridPoint(0, 0.0, SweepResult(None, (), {}), rec)  # type: ignore[arg-type]


def test_tracker_noise_moves_the_edge_of_a_tip_that_leaves_its_plateau_slowly() -> None:
    # 0.06 tip deg per knob deg past the edge: the 1 deg threshold falls 17 deg out, and
    # 0.2 deg of noise moves it by more than 2 deg
    unsure = noise_bound_edges([_point(0.0, exit_slope=0.06)], TRACKER_NOISE_DEG)
    assert unsure == {(0, 0.0, "dead_zone_pos_deg"), (0, 0.0, "dead_zone_neg_deg")}


def test_a_creeping_plateaus_edge_is_the_products_whatever_the_noise() -> None:
    # 0.05 tip deg per knob deg over 40 deg: 2 deg of creep, twice the truth's threshold; read
    # off the plateau's line (session 21) the noise moves it by < 0.5 deg
    assert noise_bound_edges([_point(0.05)], TRACKER_NOISE_DEG) == set()


def test_a_flat_plateaus_edge_is_the_products_whatever_the_noise() -> None:
    assert noise_bound_edges([_point(0.0)], TRACKER_NOISE_DEG) == set()


def test_without_tracker_noise_no_edge_is_left_out() -> None:
    assert noise_bound_edges([_point(0.05)], 0.0) == set()


def test_the_tip_truth_with_noise_reads_the_noisy_tip_reproducibly() -> None:
    p = _point(0.05)
    a = tip_truth(p, tip_noise_deg=TRACKER_NOISE_DEG, noise_seed=1)
    assert a == tip_truth(p, tip_noise_deg=TRACKER_NOISE_DEG, noise_seed=1)
    assert a != tip_truth(p)


def test_an_unsure_edge_gives_no_offset_reading_and_the_backlash_still_does() -> None:
    p = _point(0.05)
    p = GridPoint(0, 0.0, SweepResult(None, (), {"dead_zone_pos_deg": (25.0,),
                                                  "backlash_pos_deg": (3.0,)}),  # type: ignore[arg-type]
                  p.recording)
    run = type("Run", (), {"points": [p]})()
    truth = {(0, 0.0): {"dead_zone_pos_deg": 20.0, "backlash_pos_deg": 1.0}}
    got = offset_readings([run], truth, unsure={(0, 0.0, "dead_zone_pos_deg")})  # type: ignore[list-item]
    assert {k: v for k, v in got[(0, 0.0)].items() if v} == {"backlash_pos_deg": [2.0]}
