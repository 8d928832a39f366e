"""The release path's slope for method ours: the product's ratio to the locus of backlash ends.

The ends of all backlashes of one side lie on a line of slope ``omega / (1 - beta)``; a
product whose tip, once released, runs shallower or steeper than that locus (a lumped
catheter's 7 % shallower) shows it only on the tracker: a released tendon's current is
friction only. The data sheet's tracked ``release_omega`` gives the ratio on its unit, and each
unit's release line gets that ratio times its own locus slope while still passing through its
own backlash end at the calibration amplitude (session 7). The ratio itself and its range:
:mod:`tsmd.compensation.release_ratio` (the sheet loader checks it too).
"""

from __future__ import annotations

from tsmd.compensation.tension_play_params import BETA_RANGE

FAR_ZERO_LOAD_DEG = 89.0
"""A moved zero-load point stays within +-this (the profile keeps x0 within +-90 deg)."""


def release_through_amplitude(beta: float, zero_load_deg: float, amplitude_deg: float,
                              ratio: float) -> tuple[float, float]:
    """(beta', x0') whose release line has ``ratio`` times the slope of (beta, x0)'s and passes
    through the same backlash end at the amplitude: ``A - beta (A - x0) = A - beta' (A - x0')``.
    The loaded line and the backlash identified at the amplitude are unchanged."""
    if ratio == 1.0:
        return beta, zero_load_deg
    lo, hi = BETA_RANGE
    backlash = beta * (amplitude_deg - zero_load_deg)  # signed: negative on the negative side
    # never shallower than the loaded line, and x0' within the profile's range (+-FAR_ZERO_LOAD)
    floor = max(lo + 0.01, abs(backlash) / (abs(amplitude_deg) + FAR_ZERO_LOAD_DEG))
    b = min(max(1.0 - (1.0 - beta) / ratio, floor), hi)
    return b, amplitude_deg - backlash / b
