"""A table row bent by the product's templates, their knees moved to the unit's and shifted by
the level grid at once (jawcrimp's sheet, session 22): the inverse stays exact, the output
continuous and between its branches."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st
from support.play import assert_model_continuous_between_branches, assert_model_of_inverse_follows
from test_compensation_loaded_shape import shapes

from tsmd.compensation.level_grid import LevelGrid
from tsmd.compensation.loaded_shape import LoadedShape, steepest_slope
from tsmd.compensation.ours_table import OursKnob
from tsmd.compensation.tension_play_params import BETA_RANGE, TensionPlayParams

ANGLES = (-90.0, 0.0, 60.0, 90.0)


def params(shape_pos: LoadedShape, shape_neg: LoadedShape, shifts: tuple[float, ...],
           knees: tuple[float, float, float, float], h_pos: float = 0.8, h_neg: float = -0.8,
           omega: float = 1.4, beta: float = 0.1) -> TensionPlayParams:
    grid = (-90.0, 90.0)
    level = LevelGrid(ANGLES, shifts[:4], tuple(-s for s in shifts[4:]))
    return TensionPlayParams(omega, h_pos, h_neg, grid, (25.0, 27.0), (-25.0, -27.0),
                             (beta,) * 2, (beta,) * 2, (-60.0,) * 2, (60.0,) * 2,
                             shape_pos=shape_pos, shape_neg=shape_neg, level_grid=level,
                             loaded_knee_deg=knees[:2], sheet_loaded_knee_deg=knees[2:])


random_params = st.builds(
    params, shapes(), shapes(),
    st.tuples(*[st.floats(-3.0, 3.0)] * 8),
    st.tuples(*[st.floats(10.0, 20.0)] * 4),
    h_pos=st.floats(-8.0, 8.0), h_neg=st.floats(-8.0, 8.0), omega=st.floats(0.5, 3.0),
    beta=st.floats(0.0, BETA_RANGE[1]))


@given(random_params, st.floats(-90.0, 90.0),
       st.lists(st.floats(-100.0, 100.0), min_size=1, max_size=60))
@settings(max_examples=80, deadline=None)
def test_the_model_of_a_bent_shifted_rows_inverse_gives_the_desired_output(
        p: TensionPlayParams, other: float, path: list[float]) -> None:
    assert_model_of_inverse_follows(OursKnob.from_params(p).at(other), path)


@given(random_params, st.floats(-90.0, 90.0),
       st.lists(st.floats(-120.0, 120.0), min_size=2, max_size=60))
@settings(max_examples=80, deadline=None)
def test_a_bent_shifted_row_stays_continuous_and_between_its_branches(
        p: TensionPlayParams, other: float, xs: list[float]) -> None:
    b = OursKnob.from_params(p).at(other)
    # a moved knee squeezes a piece by at most the knee ratio's lower bound (0.8)
    steepest = (p.omega * steepest_slope(p.shape_pos, p.shape_neg) / 0.8
                / (1.0 - BETA_RANGE[1]) * (1.0 + 1e-6) + 1e-9)
    assert_model_continuous_between_branches(b, xs, steepest, tol=1e-6)
