"""Where the release ends, read from the calibration current, and the release line drawn to it
(session 18)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from support.profiles import assert_sheet_knob_field_round_trips

from tsmd.calibration.release_end import end_ratio, read_release_end, release_end_ratio
from tsmd.calibration.tension_play_fit import SweepCurrent, fit_tension_play
from tsmd.compensation.safety import KnobLimits
from tsmd.compensation.tension_play import release_line
from tsmd.profile import (
    DeviceKnob,
    ReferencePoint,
)

PERIOD_S = 0.004
D_POS, D_NEG, X0_POS, X0_NEG, BACKLASH = 20.0, -22.0, 12.0, -13.0, 12.0
END_POS, END_NEG = 31.0, -28.0
QUANTUM_A = 0.002
KNOB = DeviceKnob(1.3, ReferencePoint(90.0, 80.0), ReferencePoint(-90.0, -80.0),
                  KnobLimits(-90.0, 90.0, 120.0, 2000.0))


def released_A(x_deg: np.ndarray, end_deg: float) -> np.ndarray:
    """The released tendon's share, steepening toward the reversal, zero past its end."""
    h = np.maximum(x_deg - end_deg, 0.0)
    return 0.00015 * h + 0.000002 * h * h


def sweep(other_deg: float = 0.0, seed: int = 0, ramp: bool = True) -> SweepCurrent:
    """A +-90 deg sine sweep: friction, the loaded tension ramps, after each reversal the
    released tendon's ramp down to its end (``ramp``), 1 mA noise, 2 mA quantisation."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 50.0, PERIOD_S)
    pos = -90.0 * np.cos(2 * math.pi * 0.04 * t)
    v = np.gradient(pos)
    current = 0.02 * np.sign(v)
    current += np.where((v > 0) & (pos > D_POS), 0.003 * (pos - X0_POS), 0.0)
    current += np.where((v < 0) & (pos < D_NEG), 0.003 * (pos - X0_NEG), 0.0)
    if ramp:
        current += np.where(v < 0, released_A(pos, END_POS), 0.0)
        current -= np.where(v > 0, released_A(-pos, -END_NEG), 0.0)
    current = QUANTUM_A * np.round((current + rng.normal(0.0, 0.001, t.size)) / QUANTUM_A)
    return SweepCurrent(other_deg, t, pos, pos, current, D_POS, D_NEG, BACKLASH, BACKLASH)


def test_the_end_is_where_the_released_current_turns_flat_on_each_side() -> None:
    sweeps = [sweep(g, seed=i) for i, g in enumerate((-90.0, 0.0, 90.0))]
    pos, neg = read_release_end(sweeps, 1), read_release_end(sweeps, -1)
    assert pos is not None and neg is not None
    assert pos.end_deg == pytest.approx(END_POS, abs=1.0)
    assert neg.end_deg == pytest.approx(END_NEG, abs=1.0)
    assert 0.0 < pos.u95_deg < 2.0 and pos.half_cycles >= 5


def test_a_released_current_without_a_ramp_has_no_end() -> None:
    sweeps = [sweep(g, seed=i, ramp=False) for i, g in enumerate((-90.0, 0.0, 90.0))]
    assert read_release_end(sweeps, 1) is None


def test_too_few_half_cycles_give_no_reading() -> None:
    s = sweep()
    short = dataclasses.replace(s, t_s=s.t_s[:7000], cmd_deg=s.cmd_deg[:7000],
                                pos_deg=s.pos_deg[:7000], current_A=s.current_A[:7000])
    assert read_release_end([short], 1) is None


def test_the_ratio_draws_the_line_from_the_backlash_end_to_the_end_at_the_plateau() -> None:
    ratio = release_end_ratio(30.0, 80.0, 90.0, 10.0, 1.0)
    assert ratio == pytest.approx(80.0 / 50.0)
    assert math.isnan(release_end_ratio(85.0, 80.0, 90.0, 10.0, 1.0))


def test_without_an_end_in_the_current_the_products_ratio_stays() -> None:
    sweeps = [sweep(g, seed=i, ramp=False) for i, g in enumerate((-90.0, 0.0, 90.0))]
    assert end_ratio(sweeps, 1, 0.0, [80.0], [90.0], 10.0, [1.0], 0.95, (0.7, 1.3)) == 0.95


def test_an_implausible_ratio_from_the_end_keeps_the_products() -> None:
    sweeps = [sweep(g, seed=i) for i, g in enumerate((-90.0, 0.0, 90.0))]
    assert end_ratio(sweeps, 1, 0.0, [80.0], [90.0], 10.0, [0.5], 0.95, (0.7, 1.3)) == 0.95


@pytest.mark.parametrize("offset", [0.0, 1.5, 4.0])
def test_with_the_sheets_offset_the_fitted_release_reaches_the_plateau_at_the_end(
        offset: float) -> None:
    knob = dataclasses.replace(KNOB, reference_release_end_offset_deg=offset)
    sweeps = [sweep(g, seed=i) for i, g in enumerate((-90.0, 0.0, 90.0))]
    p = fit_tension_play(sweeps, knob)
    read = read_release_end(sweeps, 1)
    assert read is not None
    ends = []
    for i in range(3):
        slope, icpt = release_line(p.omega, p.height_pos_deg, p.dead_zone_pos_deg[i],
                                   p.backlash_gain_pos[i], p.zero_load_pos_deg[i])
        ends.append((p.height_neg_deg - icpt) / slope)
    assert np.mean(ends) == pytest.approx(read.end_deg + offset, abs=0.3)


def test_the_sheets_offset_round_trips_and_is_range_checked() -> None:
    assert_sheet_knob_field_round_trips("reference_release_end_offset_deg", 0, 0.9, 30.0)
