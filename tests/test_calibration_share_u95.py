"""The part of a backlash the current cannot show: the share's unit part that the slope ratio
leaves, as a reported half-width that no sweep narrows (docs/calibration.md, session 18)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tsmd.calibration.estimate import Estimate, point_estimates
from tsmd.calibration.identify import _share_u95_deg
from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import HalfCycle, SweepResult

LINE = replace(IdentifyOptions(), backlash="fraction", backlash_fraction=0.93,
               release_level="line")
GRID = np.arange(0.0, 110.0, 0.05)


def _approach(time_constant_deg: float) -> np.ndarray:
    """Direction-signed current after a reversal closing its gap to a gently rising release
    line over ``time_constant_deg`` of knob travel (noise-free)."""
    return 0.1 + 0.001 * GRID - 1.1 * np.exp(-GRID / time_constant_deg)


def _half_width(time_constant_deg: float) -> float:
    k = round(3.0 * time_constant_deg / 0.05)
    return _share_u95_deg(GRID, _approach(time_constant_deg), k, 0.93, LINE, None)


def test_a_slower_approach_to_the_release_line_reports_a_wider_backlash() -> None:
    # the travel per unit of share near the end grows with the approach's length
    narrow, wide = _half_width(3.0), _half_width(6.0)
    assert narrow > 0.0
    assert wide / narrow == pytest.approx(2.0, rel=0.1)


def test_the_reported_half_width_adds_what_no_sweep_narrows_but_the_gate_does_not() -> None:
    e = Estimate(20.0, 1.0, 4, 0.5, 0.6, 5, unit_u95_deg=2.0)
    assert e.reported_u95_deg == pytest.approx(np.hypot(1.0, 2.0))
    assert e.tip_cost_deg(1.5) == pytest.approx(1.5)


def _sweep(*halves: HalfCycle) -> SweepResult:
    t = np.arange(10) * 0.01
    data = Conditioned(t, t, t, t, t, 100.0, 0.001, 0.0005, ())
    return SweepResult(data, halves, {"backlash_neg_deg": (20.0, 21.0, 20.5),
                                      "backlash_pos_deg": (19.0, 19.5)})


def test_a_grid_points_backlash_carries_its_half_cycles_median_share_half_width() -> None:
    rising = [HalfCycle(1, 0, 5, True, backlash_deg=20.0, share_u95_deg=w) for w in (1.0, 3.0,
                                                                                      2.0)]
    falling = HalfCycle(-1, 5, 9, True, backlash_deg=19.0)  # a rule without it: NaN
    (est,) = point_estimates([_sweep(*rising, falling)])
    assert est["backlash_neg_deg"].unit_u95_deg == pytest.approx(2.0)
    assert est["backlash_pos_deg"].unit_u95_deg == 0.0
    assert est["backlash_neg_deg"].reported_u95_deg > est["backlash_neg_deg"].u95_deg
