"""The rackgrease plant (session 28, written blind): rack-and-pinion handle with a cocking rack,
eddy-current knob damper, ropes in grease-packed lumens, a heavy transducer head under gravity."""

from simrig.plants.rackgrease.params import NOMINAL_KNOBS, KnobConstants
from simrig.plants.rackgrease.plant import RackGreasePlant, make_rackgrease_plant

__all__ = ["NOMINAL_KNOBS", "KnobConstants", "RackGreasePlant", "make_rackgrease_plant"]
