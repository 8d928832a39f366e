"""The eighteenth plant, pronyring (written blind in session 25): a viscoelastic Pebax section
(Prony series, creep and recovery over minutes), a pull ring on a compliant bond (tilts, sets
back under all four ropes, anchors clocked off the planes), stainless ropes in PTFE liners whose
friction falls with load, along a path whose lower bend breathes."""

from simrig.plants.pronyring.params import NOMINAL_KNOBS, KnobConstants
from simrig.plants.pronyring.plant import PronyRingPlant, make_pronyring_plant

__all__ = ["NOMINAL_KNOBS", "KnobConstants", "PronyRingPlant", "make_pronyring_plant"]
