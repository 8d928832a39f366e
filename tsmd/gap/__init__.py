"""Sim-to-real gap diagnosis (`tsmd gap`).

Replays real recordings through the simulator plant, fits its base parameters on a training part,
locates the residual gap, ranks candidate unmodelled effects by held-out gap reduction and reports
how far the gap shrinks. Everything here is plain functions on arrays; see docs/gap.md.
"""

from tsmd.gap.errors import GapError

__all__ = ["GapError"]
