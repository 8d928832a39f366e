"""A handle's torque ripple (a detent's notches) in the online loaded ramp: the data sheet's
``torque_ripple_period_deg`` averaged out before the line is fitted (tsmd.online.features)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from support.online import (
    ENGAGE_A,
    FRICTION_A,
    SLOPE_A_PER_DEG,
    knob_current,
    profile_edges,
    rows,
)

from tsmd.compensation import build_compensator
from tsmd.loop import ROW_COLUMNS
from tsmd.online import OnlineError, OnlineWorker
from tsmd.online.features import LoadedRamp, RampOptions, Rejected, Stroke, loaded_ramp
from tsmd.profile import load_profile

PROFILE = Path(__file__).resolve().parents[1] / "profiles" / "example-sim.yaml"
PERIOD_DEG = 15.0
RIPPLE_A = 0.004
"""snakedent's detent: +-4 mA every 15 deg against a ramp of 2.2 mA/deg (here 3)."""
EDGE_DEG = 20.0
PHASES = np.linspace(0.0, 2.0 * math.pi, 8, endpoint=False)


def rippled_stroke(phase: float, *, end_deg: float = 60.0, seed: int = 0) -> Stroke:
    """A rising stroke through the edge with the handle's ripple locked to the knob angle."""
    rng = np.random.default_rng(seed)
    pos = np.arange(-20.0, end_deg, 0.1)
    cur = np.array([knob_current(p, 10.0, EDGE_DEG, -EDGE_DEG) for p in pos])
    cur += RIPPLE_A * np.sin(2.0 * math.pi * pos / PERIOD_DEG + phase)
    cur += 0.001 * rng.standard_normal(pos.size)
    return Stroke(0, 1, np.arange(pos.size) * 0.01, pos, pos, cur, np.zeros(pos.size),
                  pos + 20.0)


def ramp_of(stroke: Stroke, period_deg: float | None) -> LoadedRamp:
    ramp = loaded_ramp(stroke, EDGE_DEG, RampOptions(torque_ripple_period_deg=period_deg))
    assert isinstance(ramp, LoadedRamp)
    return ramp


def test_the_averaged_ramp_keeps_the_line_at_every_phase_of_the_ripple() -> None:
    for phase in PHASES:
        ramp = ramp_of(rippled_stroke(phase), PERIOD_DEG)
        assert ramp.slope_A_per_deg == pytest.approx(SLOPE_A_PER_DEG, rel=0.03)
        assert ramp.crossing_deg(FRICTION_A + ENGAGE_A) == pytest.approx(EDGE_DEG, abs=0.3)


def test_without_the_period_the_ripple_tilts_the_ramp_with_its_phase() -> None:
    slopes = [ramp_of(rippled_stroke(phase), None).slope_A_per_deg for phase in PHASES]
    assert max(abs(s / SLOPE_A_PER_DEG - 1.0) for s in slopes) > 0.15


def test_a_stroke_that_turns_back_within_half_a_period_of_the_window_gives_no_ramp() -> None:
    short = rippled_stroke(0.0, end_deg=39.0)  # the samples' window needs 8.4 deg of 14
    assert isinstance(loaded_ramp(short, EDGE_DEG), LoadedRamp)
    result = loaded_ramp(short, EDGE_DEG, RampOptions(torque_ripple_period_deg=PERIOD_DEG))
    assert isinstance(result, Rejected) and not result.stall
    assert "torque ripple" in result.reason


def make_worker(ripple: tuple[float | None, float | None] | None) -> OnlineWorker:
    comp = build_compensator(load_profile(PROFILE), "ours", 0.004)
    return OnlineWorker(comp, 0.004, ROW_COLUMNS, drain_every=25, ripple_period_deg=ripple)


def test_the_data_sheets_ripple_period_is_used_per_knob() -> None:
    worker = make_worker((PERIOD_DEG, None))
    assert [o.torque_ripple_period_deg for o in worker._knob_ramp] == [PERIOD_DEG, None]
    assert worker._knob_ramp[1] == replace(worker.ramp_options,
                                           handle_slip_deg=worker._knob_ramp[1].handle_slip_deg)


def test_a_sheet_without_a_period_estimates_exactly_as_before() -> None:
    estimates: list[Any] = []
    for ripple in (None, (None, None)):
        worker = make_worker(ripple)
        data = rows(200.0, profile_edges(worker.base_knobs, 4.0, at_s=100.0))
        for row in data:
            worker.observe(row, True)
        worker.drain()
        estimates.append([(tr.applied_deg, tr.n_ramps, tr.level_A, tr.estimate_deg)
                          for tr in worker.trackers.values()])
    assert estimates[0][0][0] == pytest.approx(4.0, abs=0.8)  # the change was followed
    assert estimates[0] == estimates[1]


@pytest.mark.parametrize("period", [0.0, -15.0])
def test_a_bad_ripple_period_is_refused_in_one_line(period: float) -> None:
    with pytest.raises(OnlineError, match="ripple_period_deg must be > 0"):
        make_worker((period, None))
