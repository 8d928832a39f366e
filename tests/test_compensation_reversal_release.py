"""A release line per reversal (tsmd.compensation.reversal_release) in the tension play."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from support.play import (
    assert_model_continuous_between_branches,
    assert_model_continuous_within_its_play,
    assert_model_of_inverse_follows,
)

from tsmd.compensation.ours import OursCompensator
from tsmd.compensation.ours_table import OursKnob
from tsmd.compensation.reversal_release import (
    ReleaseEndShape,
    release_end_shape_from_mapping,
    release_end_shape_to_mapping,
)
from tsmd.compensation.tension_play import Branches, model_step, rest_state
from tsmd.compensation.tension_play_params import (
    BETA_RANGE,
    TensionPlayParams,
    tension_play_from_mapping,
    tension_play_to_mapping,
)

SHAPE = ReleaseEndShape((0.5, 2.0 / 3.0, 1.0), (0.7, 0.9, 1.0), (0.6, 0.85, 0.9))
STATIC_END = ReleaseEndShape((1.0,), (1.0,), (1.0,))


def params(beta_pos: float = 0.2, beta_neg: float = 0.22, x0_pos: float = -20.0,
           x0_neg: float = 15.0, h_pos: float = -1.0, h_neg: float = 1.0, omega: float = 1.4,
           shape: ReleaseEndShape | None = SHAPE) -> TensionPlayParams:
    grid = (-90.0, 90.0)
    return TensionPlayParams(omega, h_pos, h_neg, grid, (20.0, 20.0), (-22.0, -22.0),
                             (beta_pos,) * 2, (beta_neg,) * 2, (x0_pos,) * 2, (x0_neg,) * 2,
                             release_end=shape)


def knob(p: TensionPlayParams) -> Branches:
    return OursKnob.from_params(p).at(0.0)


def shapes() -> st.SearchStrategy[ReleaseEndShape]:
    return st.lists(st.tuples(st.floats(0.2, 1.5), st.floats(0.3, 2.0)), min_size=1,
                    max_size=4).map(lambda rs: ReleaseEndShape(
                        tuple(0.3 + 0.3 * i for i in range(len(rs))), tuple(r[0] for r in rs),
                        tuple(r[1] for r in rs)))


random_params = st.builds(
    params,
    beta_pos=st.floats(0.0, BETA_RANGE[1]),
    beta_neg=st.floats(0.0, BETA_RANGE[1]),
    x0_pos=st.floats(-60.0, 30.0),
    x0_neg=st.floats(-30.0, 60.0),
    h_pos=st.floats(-8.0, 8.0),
    h_neg=st.floats(-8.0, 8.0),
    omega=st.floats(0.5, 3.0),
    shape=shapes(),
)


def release_end_after(b: Branches, x_rev: float) -> float:
    """Where the output reaches the far plateau after a reversal at ``x_rev`` (knob deg)."""
    state = model_step(rest_state(0.0, b), x_rev, b)
    flat = b.falling(b.falling_flat.hi_deg) if b.falling_flat else 0.0
    for x in np.arange(x_rev, -30.0, -0.01):
        state = model_step(state, float(x), b)
        if state.y_deg <= flat + 1e-9:
            return float(x)
    raise AssertionError("never reached the plateau")


def test_the_shape_is_linear_between_its_knots_and_held_beyond() -> None:
    assert SHAPE.at(0.1) == (0.7, 0.6)
    assert SHAPE.at(1.4) == (1.0, 0.9)
    assert SHAPE.at(5.0 / 6.0) == pytest.approx((0.95, 0.875))


def test_a_shape_reads_back_from_its_mapping_and_bad_ones_are_refused() -> None:
    assert release_end_shape_from_mapping(release_end_shape_to_mapping(SHAPE), "s") == SHAPE
    with pytest.raises(ValueError, match="strictly increasing"):
        release_end_shape_from_mapping({"reversal_fraction": [1.0, 0.5],
                                        "end_ratio": [1.0, 1.0], "slope_ratio": [1.0, 1.0]},
                                       "s")
    with pytest.raises(ValueError, match="end_ratio"):
        release_end_shape_from_mapping({"reversal_fraction": [1.0], "end_ratio": [9.0],
                                        "slope_ratio": [1.0]}, "s")
    with pytest.raises(ValueError, match="needs exactly"):
        release_end_shape_from_mapping({"reversal_fraction": [1.0], "end_ratio": [1.0]}, "s")


def test_a_profile_block_keeps_its_shape_and_one_without_writes_none() -> None:
    p = params()
    assert tension_play_from_mapping(tension_play_to_mapping(p)) == p
    plain = params(shape=None)
    assert "release_end_shape" not in tension_play_to_mapping(plain)
    assert tension_play_from_mapping(tension_play_to_mapping(plain)).release_end is None


def test_without_a_shape_the_branches_and_commands_are_the_static_models() -> None:
    plain = OursKnob.from_params(params(shape=None))
    assert plain.at(0.0) == dataclasses.replace(knob(params()), release_end=None)
    t = np.arange(0.0, 60.0, 0.01)
    q = np.column_stack([60.0 * np.sin(0.25 * t), 30.0 * np.sin(0.1 * t)])
    out = []
    for knobs in ((plain, plain), (OursKnob.from_params(params(shape=None)),) * 2):
        comp = OursCompensator(knobs, 0.01)
        out.append(np.array([comp.command(row, 0.01) for row in q]))
        assert all(kc.state.line_slope == 0.0 for kc in comp._k)
    assert np.array_equal(out[0], out[1])


def test_the_release_ends_further_out_after_larger_reversals() -> None:
    b = knob(params())
    ends = [release_end_after(b, a) for a in (45.0, 60.0, 90.0)]
    static = release_end_after(knob(params(shape=None)), 90.0)
    assert ends[0] < ends[1] < ends[2]
    assert ends[2] == pytest.approx(static, abs=0.02)  # ratio 1 at 90 deg: the unit's own end
    assert ends[0] == pytest.approx(0.7 * static, abs=0.3)


def test_ratios_of_one_are_the_static_release() -> None:
    line = knob(params(shape=STATIC_END))
    static = knob(params(shape=None))
    for amp in (40.0, 60.0, 90.0):
        for back in (5.0, 15.0, 30.0, 60.0, 100.0):
            a = model_step(model_step(rest_state(0.0, line), amp, line), amp - back, line)
            s = model_step(model_step(rest_state(0.0, static), amp, static), amp - back, static)
            assert a.y_deg == pytest.approx(s.y_deg, abs=1e-6)


def test_a_shallower_slope_ratio_releases_along_a_shallower_line() -> None:
    shallow = knob(params(shape=ReleaseEndShape((1.0,), (1.0,), (0.8,))))
    static = knob(params(shape=None))
    at = [model_step(model_step(rest_state(0.0, b), 80.0, b), 50.0, b) for b in (shallow,
                                                                                  static)]
    p = params()
    static_slope = p.omega / (1.0 - p.backlash_gain_pos[0])  # the static release line's
    assert at[0].line_slope == pytest.approx(0.8 * static_slope, rel=1e-4)
    assert at[0].y_deg < at[1].y_deg  # the same end, reached along a shallower line


def test_a_reversal_inside_the_backlash_keeps_the_hold() -> None:
    b = knob(params())
    state = model_step(model_step(rest_state(0.0, b), 70.0, b), 69.0, b)
    assert state.line_slope > 0.0
    again = model_step(model_step(state, 70.0, b), 69.5, b)
    assert again.y_deg == pytest.approx(state.y_deg, abs=1e-9)


@given(random_params, st.lists(st.floats(-120.0, 120.0), min_size=2, max_size=60))
@settings(max_examples=100, deadline=None)
def test_output_is_continuous_and_within_its_play(p: TensionPlayParams, xs: list[float]) -> None:
    b = knob(p)
    steepest = p.omega / (1.0 - BETA_RANGE[1]) * (1.0 + 1e-6) + 1e-9
    assert_model_continuous_within_its_play(b, xs, steepest)


@given(random_params, st.lists(st.floats(-100.0, 100.0), min_size=1, max_size=60))
@settings(max_examples=100, deadline=None)
def test_model_of_the_inverse_gives_the_desired_output(p: TensionPlayParams,
                                                       path: list[float]) -> None:
    assert_model_of_inverse_follows(knob(p), path)


@given(random_params, st.floats(-90.0, 90.0),
       st.lists(st.floats(-0.05, 0.05), min_size=2, max_size=200))
@settings(max_examples=100, deadline=None)
def test_many_tiny_reversals_stay_exact_and_continuous(p: TensionPlayParams, centre: float,
                                                       wiggle: list[float]) -> None:
    b = knob(p)
    steepest = p.omega / (1.0 - BETA_RANGE[1]) * (1.0 + 1e-6) + 1e-9
    assert_model_continuous_within_its_play(b, [centre, *(centre + w for w in wiggle)],
                                            steepest)
    y = model_step(rest_state(0.0, b), centre, b).y_deg
    assert_model_of_inverse_follows(b, [y, *(y + w for w in wiggle)])


@given(random_params, st.lists(st.floats(-120.0, 120.0), min_size=2, max_size=40))
@settings(max_examples=50, deadline=None)
def test_without_a_shape_the_output_stays_between_the_branches(p: TensionPlayParams,
                                                                xs: list[float]) -> None:
    b = knob(dataclasses.replace(p, release_end=None))
    steepest = p.omega / (1.0 - BETA_RANGE[1]) * (1.0 + 1e-6) + 1e-9
    assert_model_continuous_between_branches(b, xs, steepest)
