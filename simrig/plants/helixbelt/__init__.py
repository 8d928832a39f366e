"""The ninth plant, helixbelt (written blind in session 15): a toothed-belt handle with tooth
clearance and a progressive mesh, steel tendons routed in a helix along a braided shaft (the
helix's wrap combined with the shaft's curve), a braided bending section with Masing friction."""

from simrig.plants.helixbelt.params import NOMINAL_KNOBS, HelixKnobParams
from simrig.plants.helixbelt.plant import HelixBeltPlant, make_helixbelt_plant

__all__ = ["NOMINAL_KNOBS", "HelixBeltPlant", "HelixKnobParams", "make_helixbelt_plant"]
