"""beltbraid: a twentieth catheter plant, written blind (session 27; docs/plant.md)."""

from simrig.plants.beltbraid.params import NOMINAL_KNOBS, KnobParams
from simrig.plants.beltbraid.plant import BeltBraidPlant, make_beltbraid_plant

__all__ = ["NOMINAL_KNOBS", "BeltBraidPlant", "KnobParams", "make_beltbraid_plant"]
