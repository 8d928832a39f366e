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
within the gate).
"""

from __future__ import annotations

from collections.abc import Iterable

from tsmd.online.estimator import EdgeTracker


def knob_shows(edges: Iterable[EdgeTracker], direction: int) -> bool:
    """True when any of ``edges`` (the other knob's) moved ``direction`` (+1 outward, -1
    inward) beyond its gate, or holds a fresh suspect beyond its gate that way."""
    for e in edges:
        gate = e.options.gate_deg
        if direction * e.level_deg > gate:
            return True
        if (e.suspects and e.suspect_order > e.accepted_order
                and direction * (e.suspects[-1] - e.estimate_deg) > gate):
            return True
    return False


__all__ = ["knob_shows"]
