"""Where one dead-zone edge reads against the other knob's angle, beyond the profile's coupling.

The profile's coupling has three grid points; the current's edge can depend on the other knob
beyond them (lumped 101: phi1's positive edge 0.5-0.85 deg lower with phi2 at -41..-61 deg
than at +31..+74 deg, before any change), which a single offset mistakes for a change. The
bins learn it from the accepted ramps themselves, so a shape change (every bin at once) still
moves the estimate (:class:`tsmd.online.estimator.EdgeTracker`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from statistics import median


@dataclass
class OtherKnobBins:
    """Per bin of the other knob's angle (``width_deg`` wide): the last ``window`` accepted
    measurements minus the estimate then; a bin counts from ``min_count`` of them."""

    width_deg: float
    min_count: int
    window: int
    values: dict[int, list[float]] = field(default_factory=dict)
    visits: dict[int, int] = field(default_factory=dict)
    """Per bin: how many measurements it has taken (its weight in the bins' common mean)."""

    def key(self, other_deg: float) -> int:
        """The bin of ``other_deg`` (0 for a non-finite angle)."""
        return math.floor(other_deg / self.width_deg) if math.isfinite(other_deg) else 0

    def learned(self, key: int) -> bool:
        return len(self.values.get(key, [])) >= self.min_count

    def teach(self, key: int, value_deg: float) -> None:
        self.values[key] = [*self.values.get(key, []), value_deg][-self.window:]
        self.visits[key] = self.visits.get(key, 0) + 1

    def bias_deg(self, other_deg: float) -> float:
        """How far the edge reads in ``other_deg``'s bin beyond the estimate (0 until the bin
        has ``min_count`` measurements)."""
        own = self._median(self.key(other_deg))
        return 0.0 if own is None else own - self._mean_deg()

    def learning_lean_deg(self, other_deg: float, direction: int) -> float:
        """How far a bin one measurement short of ``min_count`` reads ``direction`` (+1 or -1)
        beyond the estimate: the median of its measurements when every one of them lies that
        way from the learned bins' common mean, else 0 (learned or emptier bins, mixed signs).
        A reading beyond the gate there may be the bin's own lean, not a change (planetwist 3,
        no change: phi2's negative edge +1.43, +1.37 at phi1 -37..-46 deg, then +2.53)."""
        own = self.values.get(self.key(other_deg), [])
        if self.learned(self.key(other_deg)) or len(own) < self.min_count - 1 or not own:
            return 0.0
        leans = [v - self._mean_deg() for v in own]
        if not all(direction * v > 0.0 for v in leans):
            return 0.0
        return median(leans)

    def biases_deg(self) -> dict[str, float]:
        """Each bin's bias at its middle, keyed by the bin's lower angle (for the status)."""
        return {f"{k * self.width_deg:g}": round(self.bias_deg((k + 0.5) * self.width_deg), 3)
                for k in sorted(self.values)}

    def _median(self, key: int) -> float | None:
        return median(self.values[key]) if self.learned(key) else None

    def _mean_deg(self) -> float:
        """The learned bins' medians averaged, weighted by their visits: the part of the bins
        they all share, which belongs to the estimate and is taken out of every bin.

        Without it the estimate and the bins are not pinned against each other (a ramp's
        measurement is its raw offset minus its bin's, the bin's is the raw offset minus the
        estimate then): any split of a common offset between them is stable, so noise walked
        the estimate (lumped 102, no change, 400 s: 0.62/0.70 deg)."""
        learned = [(m, self.visits.get(k, 0)) for k in self.values
                   if (m := self._median(k)) is not None]
        weight = sum(w for _, w in learned)
        return sum(m * w for m, w in learned) / weight if weight > 0 else 0.0


__all__ = ["OtherKnobBins"]
