"""``make_lumped_plant``: the ``module:factory`` entry point, parameters from plain mappings."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import fields, replace
from typing import Any

from simrig.plant import PlantLoadError
from simrig.plants.lumped.params import NOMINAL_KNOBS, LumpedEffects, LumpedKnobParams
from simrig.plants.lumped.plant import LumpedPlant

_EFFECT_NAMES = frozenset(f.name for f in fields(LumpedEffects))
_KNOB_NAMES = frozenset(f.name for f in fields(LumpedKnobParams))


def make_lumped_plant(knobs: Sequence[Mapping[str, Any]] | None = None, n_lumps: int = 4,
                      **effects: float) -> LumpedPlant:
    """Build the nominal lumped plant; ``knobs`` overrides per-knob constants
    (``[{"slack_pos_mm": 2.0}, {}]``), other keywords are :class:`LumpedEffects` fields."""
    unknown = sorted(set(effects) - _EFFECT_NAMES)
    if unknown:
        raise PlantLoadError(f"unknown plant parameter {unknown[0]!r}; known: knobs, n_lumps, "
                             + ", ".join(sorted(_EFFECT_NAMES)))
    overrides = list(knobs) if knobs is not None else [{}, {}]
    if len(overrides) != 2:
        raise PlantLoadError(f"knobs must list 2 knobs, got {len(overrides)}")
    built = []
    for i, (base, over) in enumerate(zip(NOMINAL_KNOBS, overrides, strict=True)):
        if not isinstance(over, Mapping):
            raise PlantLoadError(f"knobs[{i}] must be a mapping, got {over!r}")
        bad = sorted(set(over) - _KNOB_NAMES)
        if bad:
            raise PlantLoadError(f"knobs[{i}]: unknown parameter {bad[0]!r}")
        built.append(replace(base, **dict(over)))
    return LumpedPlant(built, LumpedEffects(**effects), n_lumps=n_lumps)
