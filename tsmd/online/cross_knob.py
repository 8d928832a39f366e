"""Whether the other knob shows a change too: what a shape change does and a knob's own
wandering does not.

A slack or sheath-curvature change moves every tendon's path through the sheath, so both
knobs' dead-zone edges move the same way (outward: more slack or more wrap). The coil-pipe
plant's phi1 crossings, though, read 2-3 deg outward for minutes without any change (units 1
and 2, 600 s of mixed use: followed on both edges of phi1 as a change at 138 s while phi2's
edges read where they were, and tracking was worse than with online off; unit 1 read 0 and
+2.05 deg at the same phase of the same periodic command, 100 s apart). A knob's change is
therefore followed only once the other knob's edges show it too: one of them already moved
that way beyond its gate, or holds a fresh suspect that way (newer than its last reading
within the gate). A change also reads on the other knob below its gate first (coilpipe 1, +0.5
mm of slack: phi1's first crossings +0.83/+0.92 deg, then +3.65/+3.80), so both of its edges'
latest readings leaning that way by ``other_knob_lean`` of the gate count too; coilpipe's
one-knob shift leaves the other knob's edges reading either way around their estimates.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from tsmd.online.estimator import EdgeTracker


def knob_shows(edges: Iterable[EdgeTracker], direction: int) -> bool:
    """True when any of ``edges`` (the other knob's) moved ``direction`` (+1 outward, -1
    inward) beyond its gate, or holds a fresh suspect beyond its gate that way, or when all of
    them last read that way by ``other_knob_lean`` of the gate."""
    edges = list(edges)
    if edges and all(_leans(e, direction) for e in edges):
        return True
    for e in edges:
        gate = e.options.gate_deg
        if direction * e.level_deg > gate:
            return True
        if (e.suspects and e.suspect_order > e.accepted_order
                and direction * (e.suspects[-1] - e.estimate_deg) > gate):
            return True
    return False


def _leans(e: EdgeTracker, direction: int) -> bool:
    """The edge's latest reading lies ``direction`` from its estimate by at least
    ``other_knob_lean`` of its gate (never with the lean off or before any reading)."""
    lean = e.options.other_knob_lean * e.options.gate_deg
    reading = e.last_reading_deg - e.estimate_deg
    return lean > 0.0 and math.isfinite(reading) and direction * reading >= lean


__all__ = ["knob_shows"]
