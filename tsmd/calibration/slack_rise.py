"""The dead zone ends at the current's first sustained rise out of the slack level.

:func:`tsmd.calibration.pieces.constant_phase` takes the last long flat run that does not
stand far above the lowest one. Behind a geared handle that is not enough: the loaded current
climbs in steps, one per tooth of mesh, flat between them, and where a step lies less than half
the loaded swing above the slack (a spur-gear handle near the end of its travel with the other
knob bent: warmgear's development units 2, 3, 6 and 8, plant alone, read 10-48 deg beyond the
tip) that flat stretch was read as the dead zone. Those steps come after the load has already
risen out of the slack level for many degrees at the loaded ramp's own slope; the release
branch before the dead zone rises too, but gently or only over a short step (where the tip
re-enters the dead zone), and after such a release step the current rests on the dead zone's
level for longer than the step took (nitinol's 7-13 deg step at the loaded slope is followed by
~40 deg of level), where on the loaded branch it rests less than it climbed. So the constant
phase is the last long run before the first gap between runs that rises at least as steeply
as the loaded ramp over at least twice a level's length and is followed by a shorter rest.

"As steeply" allows for the loaded ramp's own unevenness: its slope is read over the last
quarter of the travel, gear flats and mesh ripple included, and a rise that *is* the loaded
branch (from the edge to the first tooth flat) measures 0.97-1.09 times it (warmgear
development units 1-8, full stack, 78 such rises), so a plain ``>=`` read it as a release step
by chance (unit 3, phi2 at phi1 0: 0.998, D read 71.5 deg against the tip's 23.4). The release
branch's rises that are long enough and followed by a shorter rest stay at or below 0.42 times
it (the same runs, 182 gaps walked; session 20: at most 0.44), so the rise counts from
``SUSTAINED_RISE_SLOPE_SHARE`` of it.
"""

from __future__ import annotations

import numpy as np

from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.pieces import flat_runs, slope_per_deg
from tsmd.calibration.signal import FloatArray

SUSTAINED_RISE_LEVELS = 2.0
"""A sustained rise spans at least this many times ``min_level_deg`` of travel (the short step
where the released tendon drops its last tension spans 1-3.5 deg on warmgear)."""

SUSTAINED_RISE_SLOPE_SHARE = 0.7
"""A sustained rise climbs at least this share of the loaded ramp's slope (see the module: the
loaded branch itself measures 0.97-1.09 of it, the release branch's long rises at most 0.42)."""


def before_sustained_rise(pieces: list[tuple[int, int]], flat: list[bool], step: float,
                          opts: IdentifyOptions, yg: FloatArray,
                          chosen: tuple[int, int]) -> tuple[int, int]:
    """``chosen`` (the constant phase, start and stop on the grid), or the last long flat run
    before it that the current leaves by a sustained rise (see the module) when the walk from
    the lowest long run meets one first (the load keeps rising: the run after the rise is
    shorter than the rise)."""
    runs = [r for r in flat_runs(pieces, flat) if (r[1] - r[0]) * step >= opts.min_level_deg]
    loaded = slope_per_deg(yg[int(0.75 * yg.size):], step)
    if chosen not in runs or loaded <= 0.0:
        return chosen
    levels = [float(np.median(yg[a:b])) for a, b in runs]
    lowest = int(np.argmin(levels))
    min_gap = round(SUSTAINED_RISE_LEVELS * opts.min_level_deg / step)
    for here, after in zip(runs[lowest:runs.index(chosen)], runs[lowest + 1:], strict=False):
        a, b = here[1], after[0]
        rests = after[1] - after[0]
        if (b - a >= min_gap and rests < b - a
                and slope_per_deg(yg[a:b + 1], step) >= SUSTAINED_RISE_SLOPE_SHARE * loaded):
            return here
    return chosen
