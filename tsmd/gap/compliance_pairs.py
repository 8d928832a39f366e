"""Which pair of loads the compliance figure is read at, chosen on the data sheet's units alone.

The load contrast at 40 against 60 deg is what most plants' units scatter least on, but a
heavier pair (40 against 75, the protocol's appended heavy cycles) separates a halved tendon far
better where the stretch grows little from 40 to 60 deg against the repeats' noise (notchclutch:
z 17-21 against 2-5 on development units 1-4). On planetwist the heavier pair's units scatter
more (x1.51 / 1.99 against x1.30 / 1.58: its planets take the load one after another, a unit's
own amount), and read there alone its unit 2's halved strand was lost (docs/gap.md "Session
26"); read at both pairs, each at half the level, its held-out unit 105 was lost (docs/gap.md
"Session 27"). So one pair is read, the one at which the sheet's own units would show a doubled
stretch most clearly: per knob the log of 2 less the units' spread, over the noise a further
unit's figure has (the sheet's noise of the mean times its units plus one), mean over the
knobs. The scored unit does not enter the choice. Off unless :data:`HEAVY_LOADS_DEG` is set and
the protocol has those loads.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from tsmd.gap.compliance import LEVELS_DEG, ComplianceSheet, sheet_from_units
from tsmd.gap.data import GapSeries

HEAVY_LOADS_DEG: tuple[float, float] | None = None
"""The heavier pair of loads the sheet may be read at instead (e.g. (40, 75) with
``ProtocolDesign.heavy_amp_deg`` 75); None (the default): the one pair of
:data:`tsmd.gap.compliance.CONTRAST_LEVELS_DEG`."""

DOUBLED_LOG = math.log(2.0)
"""The figure's log shift a doubled tendon stretch gives when the whole figure is stretch."""


def doubled_stretch_z(sheet: ComplianceSheet) -> float:
    """How clearly a unit of this model with its tendon stretch doubled would clear the sheet:
    per knob (log 2 - the units' spread) / the noise of a further unit's log figure against
    the sheet, mean over the knobs the sheet reads; -inf when it reads none."""
    zs = [(DOUBLED_LOG - math.sqrt(allow)) / math.sqrt(max((sheet.units + 1) * noise, 1e-12))
          for fig, noise, allow in zip(sheet.figure_deg_per_A, sheet.noise_log_var,
                                       sheet.allowance_log_var, strict=True)
          if np.isfinite(fig)]
    return float(np.mean(zs)) if zs else -math.inf


def sheet_at_chosen_loads(units: Sequence[Sequence[GapSeries]],
                          family_alpha: float = 0.05) -> ComplianceSheet | None:
    """The data sheet read at the usual loads or, when :data:`HEAVY_LOADS_DEG` is set and
    both read the load contrast, at the pair with the larger :func:`doubled_stretch_z` (a
    sheet read on the release keeps the usual pair: its premise fails there)."""
    if HEAVY_LOADS_DEG is None:
        return sheet_from_units(units, family_alpha)
    usual = sheet_from_units(units, family_alpha, LEVELS_DEG)
    if usual is None or usual.figure != "load contrast":
        return usual
    heavier = sheet_from_units(units, family_alpha, HEAVY_LOADS_DEG)
    if heavier is None or heavier.figure != "load contrast":
        return usual
    return max((usual, heavier), key=doubled_stretch_z)
