"""Sixth plant (session 12, written blind): a twisting, warming shaft with Hertzian lumen friction.

``make_twistshaft_plant(knobs=[{...}, {...}], **shaft)``; constants and their sources in
``params.py``, one tendon's lumen contact in ``tendon.py``, the plant in ``plant.py``.
"""

from simrig.plants.twistshaft.params import ShaftParams, TwistKnobParams
from simrig.plants.twistshaft.plant import NOMINAL_KNOBS, TwistShaftPlant, make_twistshaft_plant

__all__ = ["NOMINAL_KNOBS", "ShaftParams", "TwistKnobParams", "TwistShaftPlant",
           "make_twistshaft_plant"]
