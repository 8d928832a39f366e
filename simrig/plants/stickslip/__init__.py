"""Fifth plant (written blind, session 11): polymer tendons over Karnopp stick-slip sheath nodes.

``params.py`` the constants and their sources, ``laws.py`` the constitutive laws (braid toe,
Prony relaxation, pseudo-rigid-body tip with weight), ``ring.py`` one knob's quasi-static
active-set solve, ``plant.py`` the two-knob plant and its factory.
"""

from simrig.plants.stickslip.params import NOMINAL_KNOBS, StickSlipKnobParams, StickSlipParamError
from simrig.plants.stickslip.plant import StickSlipPlant, make_stickslip_plant

__all__ = ["NOMINAL_KNOBS", "StickSlipKnobParams", "StickSlipParamError", "StickSlipPlant",
           "make_stickslip_plant"]
