"""Built-in plant 8 (written blind in session 14): a superelastic NiTi spine in the bending
section (flag-shaped, temperature-dependent moment loop shared by both planes), lumens at unequal
offsets on the two sides, per-plane cover stiffness, and a lubricated sheath whose lumped contact
adds film shear (speed-dependent) to boundary friction."""

from simrig.plants.nitinol.params import NOMINAL_KNOBS, NitinolKnobParams
from simrig.plants.nitinol.plant import NitinolPlant, make_nitinol_plant

__all__ = ["NOMINAL_KNOBS", "NitinolKnobParams", "NitinolPlant", "make_nitinol_plant"]
