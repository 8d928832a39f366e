"""Where a reversal's stick phase ends in the current: the backlash end by the slope's share.

After a reversal a tendon held in a lumen contact first unloads in place (the contact sticks:
the current falls steeply and at a nearly constant rate per knob degree), then the contact
slips and the tip is let go; past that the current creeps on towards its release level for
10-20 deg while the tip moves (notchclutch: the liner's drag and the wall's friction). The
release-line share and the knee (:mod:`tsmd.calibration.knee`) both end the backlash somewhere
in that creep, where the current's slope is a few times its own scatter: on notchclutch's
development units 0-4 one half-cycle's end scattered by 1.7 deg (sd) about the tip's, up to
5.6 deg late (docs/calibration.md, session 25). The end of the steep fall is sharper: where
the slope has fallen to :data:`STICK_SLOPE_SHARE` of its steepest, the same units' ends sat
1.4-1.7 deg before the tip's 1 deg threshold with 0.2 deg of scatter per half-cycle; the
product's reading offset (measured on the data sheet's unit) takes out the constant part.
Opt-in per product (``backlash_stick_end`` in the data sheet, chosen on the sheet's unit by
:mod:`tsmd.datasheet_stick_end`): a current that falls at no steady rate has no such end.
"""

from __future__ import annotations

import numpy as np

from tsmd.calibration.knee import KNEE_SLOPE_HALF_DEG, running_slope
from tsmd.calibration.signal import FloatArray

STICK_SLOPE_SHARE = 0.15
"""The stick phase ends where the current's slope has fallen to this share of its steepest
(notchclutch development units 0-4, offline: 0.05, 0.08, 0.1, 0.15, 0.2, 0.3 tried; per
half-cycle sd 0.98, 0.55, 0.45, 0.23, 0.22, 0.23 deg, the mean per unit and knob spread least
at 0.15: -1.40..-1.69 deg)."""
STICK_SEARCH_DEG = 15.0
"""The steepest slope is searched within this much knob travel after the reversal (the stick
phase of the family's products lasts 3-10 deg; the release branch beyond is not searched)."""


def stick_end_index(grid: FloatArray, yg: FloatArray) -> int | None:
    """The index on ``grid`` (knob angle after a reversal, direction-signed, uniform) where the
    slope of the direction-signed current ``yg`` first falls below :data:`STICK_SLOPE_SHARE` of
    its steepest within :data:`STICK_SEARCH_DEG` (least-squares slope over
    ``KNEE_SLOPE_HALF_DEG`` either side); None where the current does not fall steeply or
    never levels off."""
    if grid.size < 3:
        return None
    step = float(grid[1] - grid[0])
    slope = running_slope(yg, round(KNEE_SLOPE_HALF_DEG / step), step)
    search = np.flatnonzero((grid - grid[0] <= STICK_SEARCH_DEG) & np.isfinite(slope))
    if search.size == 0:
        return None
    steepest = int(search[np.argmax(slope[search])])
    if not slope[steepest] > 0.0:
        return None
    after = slope[steepest:]
    below = np.flatnonzero(np.isfinite(after) & (after < STICK_SLOPE_SHARE * slope[steepest]))
    return steepest + int(below[0]) if below.size else None
