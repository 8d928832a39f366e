"""The eleventh plant, warmgear (written blind in session 18): a spur-gear handle with a
compliant mesh and play, tendons whose slack shrinks as the shaft warms after insertion, a
fluid-filled sheath whose film is squeezed out under load, a section stiffer in one plane."""

from simrig.plants.warmgear.params import NOMINAL_KNOBS, ShaftParams, WarmGearKnobParams
from simrig.plants.warmgear.plant import WarmGearPlant, make_warmgear_plant

__all__ = ["NOMINAL_KNOBS", "ShaftParams", "WarmGearKnobParams", "WarmGearPlant",
           "make_warmgear_plant"]
