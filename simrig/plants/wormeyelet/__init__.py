"""The nineteenth plant (session 26, written blind): a worm-stage handle with a silicone damper,
stainless ropes over one lumen contact, and a spacer-disk section whose eyelets the ropes rub."""

from simrig.plants.wormeyelet.params import NOMINAL_KNOBS, WormEyeletKnob, knobs_from
from simrig.plants.wormeyelet.plant import WormEyeletPlant, make_wormeyelet_plant

__all__ = ["NOMINAL_KNOBS", "WormEyeletKnob", "WormEyeletPlant", "knobs_from",
           "make_wormeyelet_plant"]
