"""Fourth built-in plant: tendons in a compressible coil-pipe shaft with LuGre friction.

Written blind in session 10 (without reading the other plants). Physics in ``plant.py``, laws in
``laws.py``, constants and their sources in ``params.py``; docs/plant.md "Fourth plant".
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

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


def _knob(values: Mapping[str, Any] | CoilPipeKnobParams, index: int) -> CoilPipeKnobParams:
    if isinstance(values, CoilPipeKnobParams):
        knob = values
    elif not isinstance(values, Mapping):
        raise CoilPipeParamError(f"coilpipe knobs[{index}] must be a mapping of constants, "
                                 f"got {values!r}")
    else:
        known = {f.name for f in dataclasses.fields(CoilPipeKnobParams)}
        unknown = sorted(set(values) - known)
        if unknown:
            raise CoilPipeParamError(f"coilpipe knobs[{index}]: unknown parameter "
                                     f"{', '.join(map(repr, unknown))}")
        knob = CoilPipeKnobParams(**values)
    check_knob(knob, index)
    return knob


def make_coilpipe_plant(knobs: Sequence[Mapping[str, Any] | CoilPipeKnobParams] | None = None,
                        **shared: Any) -> CoilPipePlant:
    """The plant from per-knob constants (two mappings; defaults: the nominal unit) and the
    shared ones (``shaft_stiffness_N_per_mm``, ``sheath_curvature_deg``, ...) as keywords."""
    if knobs is None:
        pair = NOMINAL_KNOBS
    else:
        if not isinstance(knobs, Sequence) or isinstance(knobs, (str, bytes)) or len(knobs) != 2:
            raise CoilPipeParamError("coilpipe knobs must be a list of 2 mappings")
        pair = (_knob(knobs[0], 0), _knob(knobs[1], 1))
    known = {f.name for f in dataclasses.fields(CoilPipePlantParams)}
    unknown = sorted(set(shared) - known)
    if unknown:
        raise CoilPipeParamError(f"unknown coilpipe parameter {', '.join(map(repr, unknown))}")
    plant_params = CoilPipePlantParams(**shared)
    check_plant(plant_params)
    return CoilPipePlant(pair, plant_params)
