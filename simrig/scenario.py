"""Scenarios that change a plant during a run: the catheter's shape changes mid-procedure.

:class:`ShapeChangePlant` wraps any :class:`simrig.plant.Plant` that can be reshaped in its own
physics parameters (a ``reshape(**changes)`` method, see :class:`Reshapable`) and applies the
change when the plant's own clock (the sum of the ``dt_s`` it was stepped by) passes ``at_s``.
Used to test that an estimator notices a shape change and to benchmark how fast it recovers.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from simrig.plant import Plant, PlantLoadError, PlantStep, as_plant_step


@runtime_checkable
class Reshapable(Protocol):
    """A plant whose sheath shape can change mid-run (e.g. ``sheath_curvature_deg``)."""

    def reshape(self, **changes: Any) -> None: ...


@dataclass(frozen=True)
class ShapeChange:
    """At ``at_s`` (plant time) call ``plant.reshape(**changes)`` once."""

    at_s: float
    changes: Mapping[str, Any] = field(default_factory=dict)


class ShapeChangePlant:
    """A plant whose shape changes at known times; implements :class:`simrig.plant.Plant`."""

    def __init__(self, plant: Plant, changes: list[ShapeChange]) -> None:
        if not isinstance(plant, Reshapable):
            raise PlantLoadError(f"{type(plant).__name__} cannot change shape mid-run "
                                 "(it has no reshape method)")
        for c in changes:
            if not (np.isfinite(c.at_s) and c.at_s >= 0.0):
                raise PlantLoadError(f"shape change time must be finite and >= 0, got {c.at_s}")
        self.plant = plant
        self.changes = sorted(changes, key=lambda c: c.at_s)
        self.t_s = 0.0
        self.applied: list[tuple[float, ShapeChange]] = []
        """(plant time it took effect, change) for every change applied so far."""
        self._next = 0

    def reset(self) -> None:
        """Back to the start: the plant is reset, but a shape already applied stays."""
        self.plant.reset()

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        self.t_s += dt_s
        while self._next < len(self.changes) and self.t_s >= self.changes[self._next].at_s:
            change = self.changes[self._next]
            self.plant.reshape(**dict(change.changes))
            self.applied.append((self.t_s, change))
            self._next += 1
        return as_plant_step(self.plant.step(dt_s, knob_deg))

    def __getattr__(self, name: str) -> Any:
        # diagnostics of the wrapped plant (tendon tensions, effects) stay reachable
        return getattr(self.plant, name)
