"""The jawcrimp plant (session 20, written blind): the drive train and the shaft's ends.

An elastomer jaw coupling (play, then a spider whose stiffness rises steeply with squeeze)
between each knob and its drum, steel ropes over plain-bushed idlers and a lumped lumen
friction node, a shaft that shortens under the ropes' load (coil gaps close first), pull rings
whose crimps creep under held load, and the heart's pulsatile push on the tip.
"""

from simrig.plants.jawcrimp.params import NOMINAL_KNOBS, JawCrimpKnob
from simrig.plants.jawcrimp.plant import JawCrimpPlant, make_jawcrimp_plant

__all__ = ["NOMINAL_KNOBS", "JawCrimpKnob", "JawCrimpPlant", "make_jawcrimp_plant"]
