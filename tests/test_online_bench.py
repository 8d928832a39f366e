"""The online benchmark's own pieces (the runs themselves are `tsmd bench online`)."""

from __future__ import annotations

import numpy as np
import pytest

from tsmd.bench.online import mixed_motion, reversal_times, shape_change
from tsmd.errors import TsmdError


def test_shape_changes_are_named_slack_or_curvature() -> None:
    assert shape_change("slack:0.5") == {"slack_delta_mm": ((0.5, 0.5), (0.5, 0.5))}
    assert shape_change("curvature:90") == {"sheath_curvature_deg": 90.0}


@pytest.mark.parametrize("bad", ["slack", "bend:3", "curvature:x"])
def test_a_bad_shape_change_is_one_line(bad: str) -> None:
    with pytest.raises(TsmdError, match="expected slack:MM or curvature:DEG"):
        shape_change(bad)


def test_reversals_are_counted_after_the_given_time() -> None:
    t = np.arange(0.0, 40.0, 0.004)
    q = 60.0 * np.sin(2 * np.pi * 0.05 * t)  # turns at 5, 15, 25, 35 s
    assert np.allclose(reversal_times(t, q, 10.0), [15.0, 25.0, 35.0], atol=0.01)


def test_mixed_motion_stays_inside_the_knob_range_and_starts_at_rest() -> None:
    t, q = mixed_motion(120.0, 3)
    assert np.all(np.abs(q) <= 60.0) and np.allclose(q[0], 0.0)
    assert len(reversal_times(t, q[:, 0], 0.0)) >= 20
