"""Lumped Dahl-friction plant: tendon pairs as chains of friction contacts, solved implicitly."""

from simrig.plants.lumped.factory import make_lumped_plant
from simrig.plants.lumped.params import NOMINAL_KNOBS, LumpedEffects, LumpedKnobParams
from simrig.plants.lumped.plant import LumpedPlant

__all__ = ["NOMINAL_KNOBS", "LumpedEffects", "LumpedKnobParams", "LumpedPlant", "make_lumped_plant"]
