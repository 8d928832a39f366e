"""The loaded-branch template (tsmd.compensation.loaded_shape, shaped_play) in method ours."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tsmd.compensation.loaded_shape import (
    LoadedShape,
    curved,
    shape_from_mapping,
    shape_to_mapping,
    shaped_height,
)
from tsmd.compensation.ours import OursCompensator
from tsmd.compensation.ours_table import ours_knobs
from tsmd.compensation.safety import KnobLimits
from tsmd.compensation.shaped_play import shaped_branches
from tsmd.compensation.tension_play import Branches, PlayState, inverse_step, model_step
from tsmd.compensation.tension_play_params import (
    BETA_RANGE,
    TensionPlayParams,
    tension_play_from_mapping,
    tension_play_to_mapping,
)

PERIOD_S = 0.004
LIMITS = KnobLimits(-90.0, 90.0, 120.0, 2000.0)
STIFFENING = LoadedShape((0.0, 5.0, 20.0, 40.0, 70.0), (0.0, 6.2, 24.0, 46.0, 73.0))
SOFT_START = LoadedShape((0.0, 2.5, 5.0, 10.0, 60.0), (0.0, 1.6, 3.6, 8.4, 58.4))


def params(omega: float = 1.5, h_pos: float = -3.0, h_neg: float = 4.0, d_pos: float = 20.0,
           d_neg: float = -22.0, beta_pos: float = 0.32, beta_neg: float = 0.33,
           x0_pos: float = 12.0, x0_neg: float = -13.0, shape_pos: LoadedShape | None = None,
           shape_neg: LoadedShape | None = None) -> TensionPlayParams:
    g = (-90.0, 90.0)
    return TensionPlayParams(omega, h_pos, h_neg, g, (d_pos,) * 2, (d_neg,) * 2,
                             (beta_pos,) * 2, (beta_neg,) * 2, (x0_pos,) * 2, (x0_neg,) * 2,
                             shape_pos=shape_pos, shape_neg=shape_neg)


@st.composite
def shapes(draw: st.DrawFn) -> LoadedShape:
    """A monotone template: 1-6 pieces, slopes 0.3-2.5."""
    n = draw(st.integers(1, 6))
    gaps = draw(st.lists(st.floats(1.0, 25.0), min_size=n, max_size=n))
    slopes = draw(st.lists(st.floats(0.3, 2.5), min_size=n, max_size=n))
    u, t = [0.0], [0.0]
    for g, s in zip(gaps, slopes, strict=True):
        u.append(u[-1] + g)
        t.append(t[-1] + s * g)
    return LoadedShape(tuple(u), tuple(t))


random_params = st.builds(
    params, omega=st.floats(0.5, 3.0), h_pos=st.floats(-8.0, 8.0), h_neg=st.floats(-8.0, 8.0),
    d_pos=st.floats(2.0, 40.0), d_neg=st.floats(-40.0, -2.0),
    beta_pos=st.floats(*BETA_RANGE), beta_neg=st.floats(*BETA_RANGE),
    x0_pos=st.floats(-10.0, 30.0), x0_neg=st.floats(-30.0, 10.0),
    shape_pos=shapes(), shape_neg=shapes())


def knob_branches(p: TensionPlayParams) -> Branches:
    return shaped_branches(p.omega, p.height_pos_deg, p.height_neg_deg, p.dead_zone_pos_deg[0],
                           p.dead_zone_neg_deg[0], p.backlash_gain_pos[0],
                           p.backlash_gain_neg[0], p.zero_load_pos_deg[0],
                           p.zero_load_neg_deg[0], p.shape_pos, p.shape_neg)


def commands(p: TensionPlayParams, path: np.ndarray) -> np.ndarray:
    comp = OursCompensator(ours_knobs((p, p)), PERIOD_S, (LIMITS, LIMITS))
    comp.reset(path[0])
    return np.array([comp.command(q, PERIOD_S) for q in path])


def sweep_path() -> np.ndarray:
    t = np.arange(0.0, 30.0, PERIOD_S)
    return np.column_stack([80.0 * np.sin(2 * math.pi * 0.05 * t),
                            50.0 * np.sin(2 * math.pi * 0.08 * t + 1.0)])


def test_a_straight_template_gives_todays_commands_bit_for_bit() -> None:
    straight = LoadedShape((0.0, 10.0, 80.0), (0.0, 10.0, 80.0))
    path = sweep_path()
    np.testing.assert_array_equal(commands(params(), path),
                                  commands(params(shape_pos=straight, shape_neg=straight), path))


def test_a_curved_template_changes_the_commands() -> None:
    path = sweep_path()
    diff = commands(params(shape_pos=STIFFENING, shape_neg=SOFT_START), path) - commands(
        params(), path)
    assert np.abs(diff).max() > 1.0


@given(random_params, st.floats(-150.0, 150.0))
@settings(max_examples=300, deadline=None)
def test_the_branches_are_exact_between_their_knots(p: TensionPlayParams, x: float) -> None:
    """The piecewise-linear branches equal the bent loaded lines' and the straight release
    lines' envelopes everywhere (every kink the templates map to is a knot)."""
    assert p.shape_pos is not None and p.shape_neg is not None
    w, hp, hn = p.omega, p.height_pos_deg, p.height_neg_deg
    dp, dn, bp, bn = (p.dead_zone_pos_deg[0], p.dead_zone_neg_deg[0], p.backlash_gain_pos[0],
                      p.backlash_gain_neg[0])
    off_p = p.shape_pos.shaped_deg[-1] - p.shape_pos.travel_deg[-1]
    off_n = p.shape_neg.shaped_deg[-1] - p.shape_neg.travel_deg[-1]
    rp = hp + w * ((x - bp * p.zero_load_pos_deg[0]) / (1 - bp) - dp + off_p)
    rn = hn + w * ((x - bn * p.zero_load_neg_deg[0]) / (1 - bn) - dn - off_n)
    up = hp + w * p.shape_pos.at(max(x - dp, 0.0)) + min(rn - hp, 0.0)
    down = hn - w * p.shape_neg.at(max(dn - x, 0.0)) + max(rp - hn, 0.0)
    b = knob_branches(p)
    tilt = 1e-6 * w * x
    assert b.rising(x) == pytest.approx(min(up, down) + tilt, abs=1e-6)
    assert b.falling(x) == pytest.approx(max(up, down) + tilt, abs=1e-6)


@given(random_params)
@settings(max_examples=200, deadline=None)
def test_shaped_branches_are_monotone_and_rising_below_falling(p: TensionPlayParams) -> None:
    b = knob_branches(p)
    assert all(np.diff(b.knots) > 0)
    assert all(np.diff(b.rising_deg) > 0) and all(np.diff(b.falling_deg) > 0)
    assert all(r <= f + 1e-9 for r, f in zip(b.rising_deg, b.falling_deg, strict=True))


@given(random_params, st.floats(1e-7, 1e-3))
@settings(max_examples=200, deadline=None)
def test_shaped_branches_are_continuous_at_the_dead_zone_edges(p: TensionPlayParams,
                                                               eps: float) -> None:
    b = knob_branches(p)
    steep = p.omega * 2.5 / (1.0 - BETA_RANGE[1]) + 1.0  # steepest possible piece
    for x in (p.dead_zone_pos_deg[0], p.dead_zone_neg_deg[0]):
        for f in (b.rising, b.falling):
            assert abs(f(x + eps) - f(x - eps)) <= steep * 2 * eps + 1e-9


@given(random_params, st.lists(st.floats(-120.0, 120.0), min_size=1, max_size=60))
@settings(max_examples=200, deadline=None)
def test_model_of_the_shaped_inverse_gives_the_desired_output(p: TensionPlayParams,
                                                              ys: list[float]) -> None:
    b = knob_branches(p)
    inv = PlayState(0.0, b.rising(0.0), 1, b.rising(0.0))
    fwd = PlayState(inv.x_deg, inv.y_deg, 1, inv.y_deg)
    for y in ys:
        inv = inverse_step(inv, y, b)
        fwd = model_step(fwd, inv.x_deg, b)
        assert fwd.y_deg == pytest.approx(y, abs=1e-6)


samples = st.one_of(st.floats(-500.0, 500.0), st.just(math.nan), st.just(math.inf))


@given(random_params, st.lists(st.tuples(samples, samples), min_size=1, max_size=120))
@settings(max_examples=40, deadline=None)
def test_shaped_commands_respect_every_limit(p: TensionPlayParams,
                                             rows: list[tuple[float, float]]) -> None:
    narrow = dataclasses.replace(p, other_knob_deg=(-1.0, 1.0))  # a small table: fast
    comp = OursCompensator(ours_knobs((narrow, narrow)), PERIOD_S, (LIMITS, LIMITS))
    q = np.array(rows, dtype=float)
    comp.reset(q[0] if np.all(np.isfinite(q[0])) else np.zeros(2))
    cmd = np.array([comp.command(row, PERIOD_S) for row in q])
    assert np.all(np.isfinite(cmd))
    assert np.all(cmd >= LIMITS.min_deg - 1e-9) and np.all(cmd <= LIMITS.max_deg + 1e-9)
    v = np.diff(cmd, axis=0) / PERIOD_S
    assert np.all(np.abs(v) <= LIMITS.max_velocity_deg_s * (1 + 1e-9) + 1e-6)
    a = np.diff(v, axis=0) / PERIOD_S
    assert np.all(np.abs(a) <= LIMITS.max_accel_deg_s2 * (1 + 1e-6) + 1e-3)


def test_the_reference_point_lies_on_the_shaped_line_through_its_height() -> None:
    h = shaped_height(90.0, 88.2, 19.25, 1.35, STIFFENING)
    assert h + 1.35 * STIFFENING.at(90.0 - 19.25) == pytest.approx(88.2)
    h_neg = shaped_height(-90.0, -87.3, -21.25, 1.35, SOFT_START)
    assert h_neg - 1.35 * SOFT_START.at(-21.25 + 90.0) == pytest.approx(-87.3)


def test_a_straight_template_counts_as_none() -> None:
    assert curved(LoadedShape((0.0, 50.0), (0.0, 50.0))) is None
    assert curved(STIFFENING) is STIFFENING


@pytest.mark.parametrize(("travel", "shaped", "reason"), [
    ((0.0,), (0.0,), "knots"),
    ((1.0, 5.0), (0.0, 5.0), "first knot"),
    ((0.0, 5.0, 5.0), (0.0, 5.0, 6.0), "increase"),
    ((0.0, 5.0, 10.0), (0.0, 5.0, 4.0), "slope"),
    ((0.0, 5.0), (0.0, math.inf), "finite"),
])
def test_an_implausible_template_is_refused_in_one_line(travel: tuple[float, ...],
                                                        shaped: tuple[float, ...],
                                                        reason: str) -> None:
    with pytest.raises(ValueError, match=reason) as err:
        shape_from_mapping({"travel_deg": list(travel), "shaped_deg": list(shaped)},
                           "loaded_shape_pos")
    assert "\n" not in str(err.value) and "loaded_shape_pos" in str(err.value)


def test_the_profile_section_keeps_its_templates_and_old_sections_load_straight() -> None:
    p = params(shape_pos=STIFFENING, shape_neg=SOFT_START)
    m = tension_play_to_mapping(p)
    assert m["loaded_shape_pos"] == shape_to_mapping(STIFFENING)
    assert tension_play_from_mapping(m) == p
    old = {k: v for k, v in m.items() if not k.startswith("loaded_shape")}
    assert tension_play_from_mapping(old) == dataclasses.replace(p, shape_pos=None,
                                                                 shape_neg=None)
