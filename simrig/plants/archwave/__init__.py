"""The archwave plant (session 19, written blind): the motor side and the anatomy side.

A strain-wave gearhead with a polymer flexspline between each motor and its knob, a motor
whose cogging and warming torque constant the data sheet does not show, spring-loaded tendon
tensioners in the handle, and a shaft laid through two bends in different planes.
"""

from simrig.plants.archwave.params import NOMINAL_KNOBS, ArchWaveKnob, ShaftPath
from simrig.plants.archwave.plant import ArchWavePlant, make_archwave_plant

__all__ = ["NOMINAL_KNOBS", "ArchWaveKnob", "ArchWavePlant", "ShaftPath", "make_archwave_plant"]
