"""How a loaded ramp's slope change counts: shrunk within its scatter, and as far as the
knob's other tendon confirms it (a sheath's friction changes both tendons of a knob alike)."""

from __future__ import annotations

import math
from statistics import median


def shrunk_ratio(ratio: float, tolerance: float) -> float:
    """A slope ratio whose change within ``tolerance`` counts as none (the slopes' scatter),
    beyond twice the tolerance counts in full (a friction change), and in between grows
    linearly: the slope used, and so the edge, never jumps at a threshold."""
    change = abs(ratio - 1.0)
    kept = change if change >= 2.0 * tolerance else 2.0 * max(change - tolerance, 0.0)
    return 1.0 + math.copysign(kept, ratio - 1.0)


def nearest_between(a_deg: float, b_deg: float, target_deg: float) -> float:
    """The point of the interval between two readings nearest ``target_deg`` (``target_deg``
    itself when the interval holds it): a crossing read with each of two slopes the ramp
    may have, where nothing says which."""
    return min(max(target_deg, min(a_deg, b_deg)), max(a_deg, b_deg))


def common_change(own: float, partner: float, tolerance: float) -> float:
    """An edge's slope change as far as the knob's other edge confirms it (a sheath's friction
    changes both tendons of a knob alike): none when the partner's goes the other way or
    stays within ``tolerance``, the edge's own beyond twice the tolerance, linear between."""
    if own * partner <= 0.0:
        return 0.0
    return own * min(max(abs(partner) / tolerance - 1.0, 0.0), 1.0)


def pooled_change(own: float, partner: float, ratios: list[float]) -> float:
    """The knob's slope change from both tendons' last slope ``ratios`` (their median, minus
    1): in full when the two sides' own changes ``own`` and ``partner`` go the same way and
    the smaller is at least a quarter of the larger, none below an eighth (one tendon's ramps
    alone run 19-27 % steep now and then: lumped 101, 1800 s), linearly between. Six ramps,
    not each side's three against its own three-ramp reference (lumped 103 phi2 after a bend:
    +11 % and +3.6 %, the second reference at the top of its 1.36-1.56 scatter)."""
    if own * partner <= 0.0 or not ratios:
        return 0.0
    agree = min(abs(own), abs(partner)) / max(abs(own), abs(partner))
    return (median(ratios) - 1.0) * min(max(8.0 * agree - 1.0, 0.0), 1.0)
