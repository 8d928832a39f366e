"""The sixteenth plant (session 23, written blind): a planetary handle stage with load sharing,
twist-coupled stranded ropes in swivel crimps, a stiffening section and blood flow on the tip."""

from simrig.plants.planetwist.params import NOMINAL_KNOBS, PlanetTwistKnob
from simrig.plants.planetwist.plant import PlanetTwistPlant, make_planetwist_plant

__all__ = ["NOMINAL_KNOBS", "PlanetTwistKnob", "PlanetTwistPlant", "make_planetwist_plant"]
