"""Where a handle's play ends after a reversal, as the current shows it (session 24).

A handle stage with tooth play between knob and drum (planetwist's planetary stage) gives,
after a reversal, a current that falls to the friction level while the loaded tendon unloads,
then *stays* there while the knob crosses the play (the drum's bearing holds it, nothing goes
through the teeth), and steps away from that level when the far flanks meet: from there the
drum turns, the released rope pays out under the section's spring, which pulls the knob along
(the current in the direction of motion drops by that pull), and the tip starts back. The
line rule ends B where the current first reaches the level, short of the tip by the play; the
data sheet's reading offset (current minus tip on its unit) adds the *sheet unit's* play. A
unit's play scatters with its tooth tolerances (planetwist: +-30 % of about 11 knob deg), which
the sheet's offset cannot know: on development unit 4 (phi1, 22 % more play) ours' release
line sat 3-4 deg inside the tip's.

Here the step is found on the direction-signed current ``y = direction * current`` (the step
is a drop of ``y``): where it is, B ends at the step's half height and the sheet's offset is
not subtracted (the unit's own reading replaces it). It is searched only where the sheet's
offset at the other knob's 0 (the handle's play is there at every angle) says the current
misses at least :data:`MIN_PLAY_DEG`, and a step is taken only within
:data:`ENGAGE_WINDOW` times that offset past the line rule's end: the step the sheet announces.
Not where the knob's B is read at the stick end (session 27: pronyring's -5 deg offset is the
stick end's, no play; :func:`tsmd.calibration.reading_offset.corrected`'s ``read_play``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tsmd.calibration.identify import resample_on_angle
from tsmd.calibration.signal import FloatArray
from tsmd.calibration.sweep_result import SweepResult

MIN_PLAY_DEG = 3.0
"""A play is searched for only where the sheet's backlash offset at the other knob's 0 is at
least this (knob deg; above the 2 deg accuracy target with margin: smaller offsets are a
rule's bias, not a flat stretch of current)."""
ENGAGE_STEP_NOISE = 4.0
"""The step's depth below the play's level, in the filtered current's noise."""
ENGAGE_HOLD_DEG = 1.0
"""The step is held at least this far, and the play's level is the median over this much."""
ENGAGE_WINDOW: tuple[float, float] = (0.5, 2.0)
"""The step is taken between these multiples of the sheet's offset past the line end."""
GRID_STEP_DEG = 0.25
TIP_MOVE_DEG = 1.0
"""How far the tip has moved where a backlash ends by the data sheet's definition (its
reference B and reading offset are read where the tip has left its plateau by 1 deg,
``tsmd.tip_truth.TIP_THRESHOLD_DEG``); the step is where the tip *starts*, so B at the step is
moved by this over the release slope (unit 0: 13.6 -> 14.35 deg, its tip 14.22; dev unit 4:
15.7 -> 16.45, its tip 16.47)."""


def engage_lag_deg(release_slope: float | None) -> float:
    """Knob travel from the play's end to the tip's 1 deg (0 without a slope)."""
    return TIP_MOVE_DEG / release_slope if release_slope and release_slope > 0 else 0.0


def engage_travel_deg(grid: FloatArray, yg: FloatArray, line_k: int, noise_A: float,
                      window_deg: tuple[float, float]) -> float | None:
    """Knob travel from the reversal (``grid[0]``) to the step's half height, on ``yg`` over
    ``grid`` (direction-signed, one half-cycle), the play's level read just past ``line_k``
    (the line rule's end); None where no step held :data:`ENGAGE_HOLD_DEG` lies between
    ``window_deg`` (travel past the line end)."""
    step = float(grid[1] - grid[0]) if grid.size > 1 else GRID_STEP_DEG
    hold = max(2, round(ENGAGE_HOLD_DEG / step))
    lo_k = line_k + round(window_deg[0] / step)
    hi_k = min(line_k + round(window_deg[1] / step), yg.size - 2 * hold)
    if line_k < 0 or lo_k >= hi_k or line_k + 2 * hold >= yg.size:
        return None
    level = float(np.median(yg[line_k + 1:line_k + 1 + hold]))
    below = yg < level - ENGAGE_STEP_NOISE * max(noise_A, 1e-12)
    for k in range(lo_k, hi_k):
        if below[k:k + hold].all():
            low = float(np.min(yg[k:k + 2 * hold]))
            half = level - 0.5 * (level - low)
            j = k
            while j > line_k + 1 and yg[j - 1] < half:
                j -= 1
            a, b = float(yg[j - 1]), float(yg[j])
            frac = (a - half) / (a - b) if a != b else 1.0
            return float(grid[j - 1] + frac * step - grid[0])
    return None


@dataclass(frozen=True)
class Engaged:
    """What :func:`engage` read: the backlashes' new values, the unit's own offsets, and per
    backlash each half-cycle's play end (its B at the step; NaN where no step showed)."""

    values: dict[str, tuple[float, ...]]
    own: dict[str, float]
    ends: dict[str, tuple[float, ...]]


def engage(result: SweepResult, shifts: dict[str, float], play_at_zero: dict[str, float],
           lag_deg: float = 0.0) -> Engaged:
    """Per backlash whose sheet offset at the other knob's 0 is at least :data:`MIN_PLAY_DEG`
    (``play_at_zero``, current minus tip: negative): each half-cycle's B at the play's end
    where its current shows the step, else ``B - shift`` (``shifts``: the offset at this grid
    point), and the mean offset the unit's own steps gave (line end minus step; only where
    every half-cycle showed one); ``lag_deg`` added to each step (:func:`engage_lag_deg`)."""
    values: dict[str, tuple[float, ...]] = {}
    own: dict[str, float] = {}
    ends: dict[str, tuple[float, ...]] = {}
    data = result.data
    for name, play in play_at_zero.items():
        if play > -MIN_PLAY_DEG:
            continue
        shift = shifts.get(name, 0.0)
        out, diffs, found = [], [], []
        for h in result.data_half_cycles:
            if h.backlash_name != name or not math.isfinite(h.backlash_deg):
                continue
            grid, yg = resample_on_angle(data.pos_deg[h.start:h.stop],
                                         h.direction * data.current_filtered_A[h.start:h.stop],
                                         h.direction, GRID_STEP_DEG)
            line_k = round(h.backlash_deg / GRID_STEP_DEG)
            window = (ENGAGE_WINDOW[0] * -play, ENGAGE_WINDOW[1] * -play)
            travel = (None if grid.size < 3
                      else engage_travel_deg(grid, yg, line_k, data.filtered_noise_A, window))
            if travel is None:
                out.append(h.backlash_deg - shift)
                found.append(math.nan)
            else:
                out.append(travel + lag_deg)
                found.append(travel + lag_deg)
                diffs.append(h.backlash_deg - travel - lag_deg)
        if out and len(out) == len(result.values.get(name, ())):
            values[name] = tuple(out)
            ends[name] = tuple(found)
            if len(diffs) == len(out):
                own[name] = float(np.mean(diffs))
    return Engaged(values, own, ends)


__all__ = ["Engaged", "engage", "engage_lag_deg", "engage_travel_deg"]
