"""The plant interface: anything that turns knob angles into tip angles and knob torques.

Users plug their own catheter model in with ``module:factory`` and keyword parameters.
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray


@dataclass(frozen=True)
class PlantStep:
    """Result of one plant step.

    ``tip_deg`` is the bending angle of the tip in the two planes (ground truth, what an EM
    tracker sees); ``knob_torque_Nm`` is the load each knob puts on its motor.
    """

    tip_deg: NDArray[np.float64]
    knob_torque_Nm: NDArray[np.float64]


@runtime_checkable
class Plant(Protocol):
    """A catheter driven by two knobs (phi1 anterior-posterior, phi2 right-left)."""

    def reset(self) -> None:
        """Return to the straight, unloaded state."""

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]
             ) -> PlantStep | tuple[ArrayLike, ArrayLike]:
        """Advance by ``dt_s``; ``knob_deg`` (shape (2,)) is where the knobs are at its end.

        The answer is a :class:`PlantStep` or a plain ``(tip_deg, knob_torque_Nm)`` pair.
        """


def as_plant_step(answer: PlantStep | tuple[ArrayLike, ArrayLike]) -> PlantStep:
    """The answer of ``Plant.step`` as a :class:`PlantStep` (a plain pair is checked first)."""
    if isinstance(answer, PlantStep):
        return answer
    try:
        tip, torque = answer
        tip_deg = np.asarray(tip, dtype=float).reshape(2)
        torque_Nm = np.asarray(torque, dtype=float).reshape(2)
    except (TypeError, ValueError):
        raise PlantOutputError(f"a plant's step() must return a PlantStep or a pair "
                               f"(tip_deg[2], knob_torque_Nm[2]), got {answer!r}") from None
    return PlantStep(tip_deg, torque_Nm)


class PlantLoadError(ValueError):
    """The configured plant factory could not be loaded or built."""


class PlantOutputError(ValueError):
    """A plant's ``step()`` answered something that is neither a PlantStep nor a pair."""


def load_plant(spec: str, params: dict[str, Any] | None = None) -> Plant:
    """Build a plant from ``"package.module:factory"`` and keyword parameters."""
    module_name, sep, attr = spec.partition(":")
    if not sep or not module_name or not attr:
        raise PlantLoadError(f"plant factory {spec!r} must look like 'package.module:factory'")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise PlantLoadError(f"cannot import plant module {module_name!r}: {exc}") from exc
    factory = getattr(module, attr, None)
    if not callable(factory):
        raise PlantLoadError(f"{module_name!r} has no callable {attr!r}")
    try:
        plant = factory(**(params or {}))
    except TypeError as exc:
        raise PlantLoadError(f"plant factory {spec!r} rejected its parameters: {exc}") from exc
    if not isinstance(plant, Plant):
        raise PlantLoadError(f"{spec!r} returned {type(plant).__name__}, which is not a Plant")
    return plant


def step_inputs(dt_s: float, knob_deg: Any) -> tuple[float, float]:
    """A plant step's arguments checked: ``dt_s >= 0`` and two finite knob angles (deg).

    Part of the protocol so that every plant refuses bad input the same way (``ValueError``).
    """
    if not dt_s >= 0.0:
        raise ValueError(f"dt_s must be >= 0, got {dt_s!r}")
    try:
        q0, q1 = (float(x) for x in knob_deg)
    except (TypeError, ValueError):
        raise ValueError(f"knob_deg must be 2 finite angles, got {knob_deg!r}") from None
    if not (math.isfinite(q0) and math.isfinite(q1)):
        raise ValueError(f"knob_deg must be 2 finite angles, got {knob_deg!r}")
    return q0, q1
