"""snakedent (session 22, written blind): a snake-bone section of rolling vertebrae, detented
knobs, steel ropes with slack over one lumen contact each (docs/plant.md, "A fifteenth plant,
written blind: snakedent")."""

from simrig.plants.snakedent.params import NOMINAL_KNOBS, SnakeDentKnob
from simrig.plants.snakedent.plant import SnakeDentPlant, make_snakedent_plant

__all__ = ["NOMINAL_KNOBS", "SnakeDentKnob", "SnakeDentPlant", "make_snakedent_plant"]
