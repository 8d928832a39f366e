"""Built-in plant 3 (blind): tendons as chains of elastic elements along the sheath, each element
with its own elasto-plastic friction contact, a recruitment toe for the slack, a bending tip with
nonlinear stiffness and Bouc-Wen hysteresis, and a small coupling between the two planes.

Written without reading the capstan or lumped plants' code (``docs/plant.md``, "A blind plant").
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from simrig.plants.segments.params import (
    NOMINAL_KNOBS,
    SegmentsKnobParams,
    SegmentsPlantParams,
    knob_params,
    plant_params,
)
from simrig.plants.segments.plant import SegmentsPlant

__all__ = ["NOMINAL_KNOBS", "SegmentsKnobParams", "SegmentsPlant", "SegmentsPlantParams",
           "make_segments_plant"]


def make_segments_plant(knobs: Sequence[Mapping[str, Any]] | None = None,
                        **settings: Any) -> SegmentsPlant:
    """The plant factory (``simrig.plants.segments:make_segments_plant``): ``knobs`` overrides
    the nominal constants per knob, the keywords are :class:`SegmentsPlantParams` fields."""
    return SegmentsPlant(knob_params(knobs), plant_params(settings))
