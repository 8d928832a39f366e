"""The loaded-branch templates over the other knob's angle, measured on a sheet's unit
(tsmd.datasheet_shape_grid) through the full simulated stack."""

from __future__ import annotations

import pytest

from simrig.family import family_member
from tsmd.datasheet_shape_grid import measure_shape_grids
from tsmd.errors import TsmdError


def test_the_other_planes_bend_straightens_a_shared_spines_knee() -> None:
    # nitinol: both planes bend one superelastic spine; bent by the other plane, it has
    # transformed already and the knob's branch loses its knee
    pos, neg = measure_shape_grids(family_member("nitinol", 0).build, [1.36, 1.32],
                                   grid_deg=(0.0, 90.0))[0]
    for side in (pos, neg):
        with_knee, straightened = side.at(0.0), side.at(90.0)
        assert with_knee.at(30.0) / 30.0 < 0.7 < straightened.at(30.0) / 30.0


def test_a_grid_with_fewer_than_two_angles_is_one_line() -> None:
    with pytest.raises(TsmdError, match="loaded-shape grid") as err:
        measure_shape_grids(family_member("nitinol", 0).build, [1.36, 1.32], grid_deg=(0.0,))
    assert "\n" not in str(err.value)
