"""The tenth plant (session 16, written blind): tendons whose friction is distributed over
ageing (rate-and-state) lumen contacts along a curved shaft (``docs/plant.md``)."""

from simrig.plants.ratestate.params import NODES, NOMINAL_KNOBS, RateStateKnobParams
from simrig.plants.ratestate.plant import RateStatePlant, make_ratestate_plant

__all__ = ["NODES", "NOMINAL_KNOBS", "RateStateKnobParams", "RateStatePlant",
           "make_ratestate_plant"]
