"""How a loaded ramp's slope change counts: shrunk within its scatter, and as far as the
knob's other tendon confirms it (a sheath's friction changes both tendons of a knob alike)."""

from __future__ import annotations

import math


def shrunk_ratio(ratio: float, tolerance: float) -> float:
    """A slope ratio whose change within ``tolerance`` counts as none (the slopes' scatter),
    beyond twice the tolerance counts in full (a friction change), and in between grows
    linearly: the slope used, and so the edge, never jumps at a threshold."""
    change = abs(ratio - 1.0)
    kept = change if change >= 2.0 * tolerance else 2.0 * max(change - tolerance, 0.0)
    return 1.0 + math.copysign(kept, ratio - 1.0)


def common_change(own: float, partner: float, tolerance: float) -> float:
    """An edge's slope change as far as the knob's other edge confirms it (a sheath's friction
    changes both tendons of a knob alike): none when the partner's goes the other way or
    stays within ``tolerance``, the edge's own beyond twice the tolerance, linear between."""
    if own * partner <= 0.0:
        return 0.0
    return own * min(max(abs(partner) / tolerance - 1.0, 0.0), 1.0)
