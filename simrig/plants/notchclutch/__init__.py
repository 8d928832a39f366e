"""The seventeenth plant (session 24, written blind): a slip clutch between knob and drum,
aramid tendons on a soaking hydrophilic liner, a laser-cut steel section whose notches close,
and a tip that rubs on the oesophageal wall."""

from simrig.plants.notchclutch.params import NOMINAL_KNOBS, NotchClutchKnob
from simrig.plants.notchclutch.plant import NotchClutchPlant, make_notchclutch_plant

__all__ = ["NOMINAL_KNOBS", "NotchClutchKnob", "NotchClutchPlant", "make_notchclutch_plant"]
