"""A reading offset the sheet measured but a calibration does not apply (its interval holds
zero) still says how far the values may sit from the tip: its |mean| + 95 % half-width goes into
the part no sweep narrows, unless the product's sample measured that part (docs/calibration.md,
session 27)."""

from __future__ import annotations

import numpy as np
import pytest

from tsmd.calibration.estimate import point_estimates
from tsmd.calibration.reading_offset import REPORT_MIN_OFFSET_DEG, left_u95_deg
from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import HalfCycle, SweepResult
from tsmd.calibration.unit_part import UnitPart, with_unit_part
from tsmd.profile.reading_offset import OffsetGrid, ReadingOffset

OTHER_DEG = (-90.0, 0.0, 90.0)
UNSURE = OffsetGrid((0.4, 0.5, 0.0), (0.5, 0.6, 0.5), (4, 4, 4))
"""B_neg read +0.4 / +0.5 / 0 deg from the tip, each within its own half-width of zero."""
SURE = OffsetGrid((-0.9, -0.9, -0.9), (0.3, 0.3, 0.3), (4, 4, 4))


def _offset() -> ReadingOffset:
    return ReadingOffset(OTHER_DEG, (("dead_zone_pos_deg", SURE), ("backlash_neg_deg", UNSURE)))


def _sweep() -> SweepResult:
    t = np.arange(10) * 0.01
    data = Conditioned(t, t, t, t, t, 100.0, 0.001, 0.0005, ())
    halves = (HalfCycle(1, 0, 5, True, backlash_deg=20.0),)
    return SweepResult(data, halves, {"backlash_neg_deg": (20.0, 21.0),
                                      "dead_zone_pos_deg": (15.0, 15.5)})


def _left(other_deg: float) -> dict[str, float]:
    return {name: left_u95_deg(_offset(), name, other_deg, REPORT_MIN_OFFSET_DEG)
            for name in ("backlash_neg_deg", "dead_zone_pos_deg")}


def test_an_unapplied_offset_leaves_its_mean_and_half_width() -> None:
    assert _left(-90.0)["backlash_neg_deg"] == pytest.approx(0.9)
    assert _left(0.0)["backlash_neg_deg"] == pytest.approx(1.1)
    assert _left(45.0)["backlash_neg_deg"] == pytest.approx(0.8)  # between the sheet's angles


def test_an_applied_offset_leaves_nothing_beyond_the_gates_half_width() -> None:
    assert _left(0.0)["dead_zone_pos_deg"] == 0.0


def test_without_a_measured_offset_nothing_is_left() -> None:
    assert left_u95_deg(None, "backlash_neg_deg", 0.0) == 0.0


def test_the_reported_half_width_carries_what_an_unapplied_offset_leaves() -> None:
    (before,) = point_estimates([_sweep()])
    (after,) = point_estimates([with_unit_part(_sweep(), None, _left(0.0))])
    assert before["backlash_neg_deg"].unit_u95_deg == 0.0
    assert after["backlash_neg_deg"].unit_u95_deg == pytest.approx(1.1)
    assert after["backlash_neg_deg"].u95_deg == before["backlash_neg_deg"].u95_deg  # the gate's
    assert after["dead_zone_pos_deg"].unit_u95_deg == 0.0


def test_a_sample_part_is_not_counted_twice() -> None:
    # the sample's errors were read with the unapplied offset in them: its part holds it
    (after,) = point_estimates([with_unit_part(_sweep(), UnitPart(None, 0.7), _left(0.0))])
    assert after["backlash_neg_deg"].unit_u95_deg == pytest.approx(0.7)
