"""A synthetic +-90 deg sweep's current (friction and a tension ramp past known edges) and the
sheet knob it is read against: the fake the plateau-height stages' tests share."""

from __future__ import annotations

import math

import numpy as np

from tsmd.calibration.tension_play_fit import SweepCurrent
from tsmd.compensation.safety import KnobLimits
from tsmd.profile import DeviceKnob, ReferencePoint

PERIOD_S = 0.004
D_POS, D_NEG, X0_POS, X0_NEG = 20.0, -22.0, 12.0, -13.0
"""The fake's dead-zone edges and the knob angles its tension ramps start from (deg)."""
SHEET_KNOB = DeviceKnob(1.5, ReferencePoint(90.0, 100.0), ReferencePoint(-90.0, -100.0),
                        KnobLimits(-90.0, 90.0, 120.0, 2000.0),
                        reference_dead_zone_pos_deg=25.0, reference_dead_zone_neg_deg=-25.0)


def sweep(other_deg: float) -> SweepCurrent:
    """A +-90 deg sweep whose current is friction and a tension ramp past the edges."""
    t = np.arange(0.0, 50.0, PERIOD_S)
    pos = -90.0 * np.cos(2 * math.pi * 0.04 * t)
    v = np.gradient(pos)
    load = np.where((v > 0) & (pos > D_POS), 0.003 * (pos - X0_POS), 0.0)
    load += np.where((v < 0) & (pos < D_NEG), 0.003 * (pos - X0_NEG), 0.0)
    current = 0.03 * np.sign(v) + load
    return SweepCurrent(other_deg, t, pos, pos, current, D_POS, D_NEG, 25.0, 25.0)
