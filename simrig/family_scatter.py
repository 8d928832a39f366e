"""Unit-to-unit scatter of every built-in plant's constants (used by :mod:`simrig.family`).

Each plant's table lives beside its nominal constants (``UNIT_SCATTER`` in its ``params``
module, with why each constant scatters that much); this module only names them, in the
order the plants are registered.
"""

from __future__ import annotations

from simrig.plants.archwave.params import UNIT_SCATTER as ARCHWAVE
from simrig.plants.beltbraid.params import UNIT_SCATTER as BELTBRAID
from simrig.plants.capstan.params import UNIT_SCATTER as CAPSTAN
from simrig.plants.coilpipe.params import UNIT_SCATTER as COILPIPE
from simrig.plants.cyclopebax.params import UNIT_SCATTER as CYCLOPEBAX
from simrig.plants.helixbelt.params import UNIT_SCATTER as HELIXBELT
from simrig.plants.jawcrimp.params import UNIT_SCATTER as JAWCRIMP
from simrig.plants.lumped.params import UNIT_SCATTER as LUMPED
from simrig.plants.nitinol.params import UNIT_SCATTER as NITINOL
from simrig.plants.notchclutch.params import UNIT_SCATTER as NOTCHCLUTCH
from simrig.plants.planetwist.params import UNIT_SCATTER as PLANETWIST
from simrig.plants.pronyring.params import UNIT_SCATTER as PRONYRING
from simrig.plants.rackgrease.params import UNIT_SCATTER as RACKGREASE
from simrig.plants.ratestate.params import UNIT_SCATTER as RATESTATE
from simrig.plants.screwrod.params import UNIT_SCATTER as SCREWROD
from simrig.plants.segments.params import UNIT_SCATTER as SEGMENTS
from simrig.plants.snakedent.params import UNIT_SCATTER as SNAKEDENT
from simrig.plants.stickslip.params import UNIT_SCATTER as STICKSLIP
from simrig.plants.twistshaft.params import UNIT_SCATTER as TWISTSHAFT
from simrig.plants.warmgear.params import UNIT_SCATTER as WARMGEAR
from simrig.plants.wormeyelet.params import UNIT_SCATTER as WORMEYELET

SCATTER: dict[str, dict[str, float]] = {
    "capstan": CAPSTAN,
    "lumped": LUMPED,
    "segments": SEGMENTS,
    "coilpipe": COILPIPE,
    "stickslip": STICKSLIP,
    "twistshaft": TWISTSHAFT,
    "screwrod": SCREWROD,
    "nitinol": NITINOL,
    "helixbelt": HELIXBELT,
    "ratestate": RATESTATE,
    "warmgear": WARMGEAR,
    "archwave": ARCHWAVE,
    "jawcrimp": JAWCRIMP,
    "cyclopebax": CYCLOPEBAX,
    "snakedent": SNAKEDENT,
    "planetwist": PLANETWIST,
    "notchclutch": NOTCHCLUTCH,
    "pronyring": PRONYRING,
    "wormeyelet": WORMEYELET,
    "beltbraid": BELTBRAID,
    "rackgrease": RACKGREASE,
}
"""Per plant, the relative half-range of a uniform draw around each constant's nominal value."""
