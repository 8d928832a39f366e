"""Seventh plant: a lead-screw handle, UHMWPE tendons that creep, a Kirchhoff-rod tip that meets
a compliant wall. Written blind (session 13), without reading the other six plants."""

from simrig.plants.screwrod.params import NOMINAL_KNOBS, NOMINAL_WALL, ScrewRodKnobParams
from simrig.plants.screwrod.plant import ScrewRodPlant, make_screwrod_plant

__all__ = ["NOMINAL_KNOBS", "NOMINAL_WALL", "ScrewRodKnobParams", "ScrewRodPlant",
           "make_screwrod_plant"]
