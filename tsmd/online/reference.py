"""What one edge's loaded current looks like at the profile's edge: the estimator's reference.

The profile is taken as right at the start of use, so the first ramps fix what the current
does at its edge (the level, the slope, the crossing's residual against the profile). A
catheter whose behaviour is still settling (the twistshaft plant's 60 s warm-up in the
patient: its ramps 8-17 % flatter afterwards, its crossings 0.6-2.2 deg further out, session
13) makes such a reference a drift. :class:`SettlingReference` therefore keeps re-learning it
from the latest ramps that read within the gate until it stops moving (the reference of
``settle_ramps`` re-learnings ago reads the latest ramps as it does now) or a change is
followed; only then is it fixed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from statistics import median

from tsmd.online.features import LoadedRamp


@dataclass(frozen=True)
class Reference:
    """The current at the profile's edge on one tendon, learned from a few ramps."""

    level_A: float
    slope_A_per_deg: float
    residual_deg: float
    """Median crossing of ``level_A`` (with ``slope_A_per_deg``) minus the profile's edge."""
    knee_residual_deg: float = math.nan
    """Median knee minus the profile's edge, outward (NaN: knees in half the ramps or fewer)."""

    def reading_deg(self, ramp: LoadedRamp, edge_deg: float) -> float:
        """Outward offset of ``ramp``'s crossing from ``edge_deg`` by this reference."""
        return ramp.side * (ramp.crossing_deg(self.level_A, self.slope_A_per_deg) - edge_deg
                            - self.residual_deg)


def learn_reference(window: list[tuple[LoadedRamp, float]]) -> Reference:
    """The reference of ``window``'s (ramp, profile edge) pairs: medians over them."""
    level_A = median(r.current_at(d) for r, d in window)
    slope = median(r.slope_A_per_deg for r, _ in window)
    residual = median(r.crossing_deg(level_A, slope) - d for r, d in window)
    knees = [r.side * (r.knee_deg - d) for r, d in window if math.isfinite(r.knee_deg)]
    knee = median(knees) if len(knees) * 2 > len(window) else math.nan
    return Reference(level_A, slope, residual, knee)


@dataclass
class SettlingReference:
    """The reference, re-learned on the last ``size`` in-gate ramps until it has settled.

    Settled once the reference of ``settle_ramps`` re-learnings ago reads the present window
    within ``offset_tol_deg`` (median) and its slope within ``slope_tol`` of the present one:
    the catheter's behaviour stopped moving under it. ``settle_ramps`` 0: fixed at once (the
    first ``size`` ramps, as until session 13)."""

    size: int
    settle_ramps: int
    offset_tol_deg: float
    slope_tol: float
    window: list[tuple[LoadedRamp, float]] = field(default_factory=list)
    history: list[Reference] = field(default_factory=list)
    current: Reference | None = None
    settled: bool = False
    relearned: int = 0
    """Times the reference was re-learned after the first (status, diagnosis)."""

    def add(self, ramp: LoadedRamp, edge_deg: float) -> bool:
        """Take a ramp that read within the gate (any ramp while nothing is learned); True when
        the reference changed."""
        if self.settled:
            return False
        self.window = [*self.window, (ramp, edge_deg)][-self.size:]
        if len(self.window) < self.size:
            return False
        if self.current is not None:
            self.relearned += 1
        self.current = learn_reference(self.window)
        self.history = [*self.history, self.current][-(self.settle_ramps + 1):]
        self.settled = self.settle_ramps <= 0 or self._stopped_moving()
        return True

    def fix(self) -> None:
        """A change was followed: the reference stays what it is (the change is against it)."""
        if self.current is not None:
            self.settled = True

    def _stopped_moving(self) -> bool:
        if len(self.history) <= self.settle_ramps:
            return False
        old, new = self.history[0], self.history[-1]
        offset = median(old.reading_deg(r, d) for r, d in self.window)
        return (abs(offset) <= self.offset_tol_deg
                and abs(old.slope_A_per_deg / new.slope_A_per_deg - 1.0) <= self.slope_tol)


__all__ = ["Reference", "SettlingReference", "learn_reference"]
