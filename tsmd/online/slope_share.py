"""Where an edge's crossings lie between the slope in use's and the ramp's own, learned while
the profile's edge was right.

A ramp's line is read through its window's centre, ~15 deg outward of the edge, so two slopes
give two crossings ~15 deg x their slopes' difference apart; which is the edge nothing in one
ramp says. Before any change is followed the edge is where the estimate is (the profile is
taken as right at the start of use), so each crossing within the gate tells which share of the
way from the slope in use's crossing to the ramp's own lands on it. Tendons differ (twistshaft
2: phi1's positive ramps run 1.05 x its reference and their own slope's crossing lands on the
edge, -0.9/-0.7 deg with the slope in use; unit 1's phi2 negative ramps, 0.94 x, land with the
slope in use), and a slack moves the line without turning it, so the same share reads the
moved edge (:attr:`tsmd.online.estimator_options.EstimatorOptions.suspect_reads_learned_share`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass
class SlopeShare:
    """The least-squares share f in ``edge = in_use + f (own - in_use)`` over the crossings
    taught, clamped to 0..1 (0: the slope in use's crossing)."""

    min_count: int = 2
    max_error: float = 0.25
    """The share counts once its standard error is at most this (of the way between the two
    crossings): two crossings a few tenths of a degree apart say nothing about it."""
    sum_dd: float = 0.0
    sum_de: float = 0.0
    sum_ee: float = 0.0
    count: int = 0

    def teach(self, in_use_deg: float, own_deg: float, edge_deg: float) -> None:
        """One crossing within the gate read both ways while the edge was at ``edge_deg``."""
        d, e = own_deg - in_use_deg, edge_deg - in_use_deg
        self.sum_dd += d * d
        self.sum_de += d * e
        self.sum_ee += e * e
        self.count += 1

    def fit(self) -> tuple[float, float]:
        """(the unclamped least-squares share, its standard error); NaN before two crossings
        that differ."""
        if self.count < 2 or self.sum_dd <= 0.0:
            return math.nan, math.nan
        f = self.sum_de / self.sum_dd
        residual = max(self.sum_ee - f * self.sum_de, 0.0) / (self.count - 1)
        return f, math.sqrt(residual / self.sum_dd)

    @property
    def share(self) -> float | None:
        """The learned share, None until ``min_count`` crossings taught it within
        ``max_error``, and while it lies beyond the two slopes by more than that (the
        crossings' own scatter, not the slopes, moved them)."""
        f, error = self.fit()
        if not (self.count >= self.min_count and error <= self.max_error
                and -self.max_error <= f <= 1.0 + self.max_error):
            return None
        return min(1.0, max(0.0, f))

    def read(self, in_use_deg: float, own_deg: float) -> float:
        """The crossing at the learned share of the way to the ramp's own (the slope in use's
        until learned)."""
        f = self.share
        return in_use_deg if f is None else in_use_deg + f * (own_deg - in_use_deg)


__all__ = ["SlopeShare"]
