"""Whether the knob's other edge shows a change too, before an edge leaves the profile's value.

A catheter's shape change moves both dead-zone edges of a knob: a slack or a sheath bend widens
both (every tendon's path or wrap grows), a path change of the shaft shifts both the same way
along the knob's axis (one edge out, the other in). One edge's readings moving on their own is
what the current does without any change (session 17, development units, 600 s of mixed use:
coilpipe 1's phi1 positive edge read +2.03 and +2.04 deg on two strokes, followed as a change
while its negative edge read -0.17 and +0.68 on either side of them, and phi1 tracked 0.6-1.3
deg worse than with online off for the 250 s it stayed; lumped 6's phi1 negative edge crept to
+0.49 deg within the gate while its positive edge stayed below the dead band, 0.1-0.2 deg worse).
So the first change away from the profile waits until the other edge of the knob shows one
as well; since session 27 the same way (``partner_confirms_same_way``: both outward or both
inward), since a catheter's relaxation after its calibration moves the whole dead zone without
a change (pronyring 1: phi1's negative edge read 2-3 deg outward for 600 s, its positive edge
1-2 deg inward; followed, phi1 tracked worse than with online off). Once a change was followed
the edges refine on their own (a correction of a follow that went too far is one edge's).
"""

from __future__ import annotations

import math
from typing import Protocol


class EdgeView(Protocol):
    """What the rule reads of an edge tracker (:class:`tsmd.online.estimator.EdgeTracker`)."""

    level_deg: float
    estimate_deg: float
    last_reading_deg: float


class SuspectView(Protocol):
    """What :func:`holds_agreeing_suspect` reads of an edge tracker."""

    frozen_for: int
    suspects: list[float]
    suspect_order: int
    accepted_order: int


class OutwardView(Protocol):
    """What :func:`holds_outward_suspect` reads of an edge tracker."""

    estimate_deg: float
    suspects: list[float]


def partner_shows_change(partner: EdgeView | None, lean_deg: float,
                         direction: int = 0) -> bool:
    """The knob's other edge followed a change, or its latest reading lies ``lean_deg`` or
    more from its estimate: either way (``direction`` 0: a widening or a shift), or that way
    (+1 outward, -1 inward: a widening or a narrowing only). True without a partner."""
    if partner is None or partner.level_deg != 0.0:
        return True
    reading = partner.last_reading_deg - partner.estimate_deg
    if direction != 0:
        reading *= direction
        return math.isfinite(reading) and reading >= lean_deg
    return math.isfinite(reading) and abs(reading) >= lean_deg


def partner_left_band(partner: EdgeView | None, deadband_deg: float) -> bool:
    """The knob's other edge followed a change or its estimate left the dead band (either way):
    an estimate within the gate may then move this edge off the profile's value too."""
    if partner is None or partner.level_deg != 0.0:
        return True
    return abs(partner.estimate_deg) > deadband_deg


def holds_outward_suspect(partner: OutwardView | None, gate_deg: float) -> bool:
    """The knob's other edge last read a suspect outward beyond the gate: then a reading of
    this edge that only the slope in use puts beyond the gate confirms it (a slack's first
    ramps: coilpipe 1, +0.5 mm, phi1's positive edge +2.79 with the slope in use, +1.25 with
    its own, after the negative edge's +3.90)."""
    return (partner is not None and bool(partner.suspects)
            and partner.suspects[-1] - partner.estimate_deg > gate_deg)


def holds_agreeing_suspect(partner: SuspectView, value_deg: float, spread_deg: float) -> bool:
    """The knob's other edge, not frozen, last read a suspect (nothing within its gate since)
    within ``spread_deg`` of ``value_deg``, the change this edge just followed on its own
    suspects: both edges of the knob agree, so the other follows too. Without it, an edge that
    followed on two suspects of its own took its partner's agreeing suspect with it (both
    cleared) and the partner stayed where it was (coilpipe 1, 60 deg bend: phi2 neg followed
    to +2.78 deg on two suspects, pos held +2.42 and stayed at 0; phi2 tracked worse than
    with online off)."""
    return (partner.frozen_for == 0 and bool(partner.suspects)
            and partner.suspect_order > partner.accepted_order
            and abs(partner.suspects[-1] - value_deg) <= spread_deg)


__all__ = ["EdgeView", "OutwardView", "SuspectView", "holds_agreeing_suspect",
           "holds_outward_suspect", "partner_left_band", "partner_shows_change"]
