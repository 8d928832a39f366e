"""The fourteenth plant (session 21, written blind): a cycloidal adapter with lost motion and
load-dependent mesh loss, a knob brake, lay-dependent lumen friction, a three-durometer Pebax
section whose neutral axis moves as it bends, and ropes that take a set when overloaded."""

from simrig.plants.cyclopebax.params import NOMINAL_KNOBS, CycloPebaxKnob
from simrig.plants.cyclopebax.plant import CycloPebaxPlant, make_cyclopebax_plant

__all__ = ["NOMINAL_KNOBS", "CycloPebaxKnob", "CycloPebaxPlant", "make_cyclopebax_plant"]
