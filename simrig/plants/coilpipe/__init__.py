"""Fourth built-in plant: tendons in a compressible coil-pipe shaft with LuGre friction.

Written blind in session 10 (without reading the other plants). Physics in ``plant.py``, laws in
``laws.py``, constants and their sources in ``params.py``; docs/plant.md "Fourth plant".
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

from simrig.plant import PlantLoadError
from simrig.plants.coilpipe.params import (
    NOMINAL_KNOBS,
    CoilPipeKnobParams,
    CoilPipeParamError,
    CoilPipePlantParams,
    check_knob,
    check_plant,
)
from simrig.plants.coilpipe.plant import CoilPipePlant

__all__ = ["NOMINAL_KNOBS", "CoilPipeKnobParams", "CoilPipeParamError", "CoilPipePlant",
           "CoilPipePlantParams", "make_coilpipe_plant"]


def _knob(values: Mapping[str, Any] | CoilPipeKnobParams) -> CoilPipeKnobParams:
    if isinstance(values, CoilPipeKnobParams):
        return values
    if not isinstance(values, Mapping):
        raise CoilPipeParamError(f"coilpipe knobs must be mappings of constants, got {values!r}")
    known = {f.name for f in dataclasses.fields(CoilPipeKnobParams)}
    unknown = sorted(set(values) - known)
    if unknown:
        raise CoilPipeParamError(f"unknown coilpipe knob parameter(s): {', '.join(unknown)}")
    return CoilPipeKnobParams(**values)


def make_coilpipe_plant(knobs: Sequence[Mapping[str, Any] | CoilPipeKnobParams] | None = None,
                        **shared: Any) -> CoilPipePlant:
    """The plant from per-knob constants (two mappings; defaults: the nominal unit) and the
    shared ones (``shaft_stiffness_N_per_mm``, ``sheath_curvature_deg``, ...) as keywords."""
    if knobs is None:
        pair = NOMINAL_KNOBS
    else:
        if isinstance(knobs, (str, bytes)) or len(knobs) != 2:
            raise PlantLoadError("coilpipe knobs must be a list of two mappings")
        pair = (_knob(knobs[0]), _knob(knobs[1]))
    known = {f.name for f in dataclasses.fields(CoilPipePlantParams)}
    unknown = sorted(set(shared) - known)
    if unknown:
        raise CoilPipeParamError(f"unknown coilpipe parameter(s): {', '.join(unknown)}")
    plant_params = CoilPipePlantParams(**shared)
    for k in pair:
        check_knob(k)
    check_plant(plant_params)
    return CoilPipePlant(pair, plant_params)
