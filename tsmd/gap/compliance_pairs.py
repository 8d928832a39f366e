"""Compliance read at two pairs of loads, named on whichever clears its own units' spread.

The load contrast at 40 against 60 deg is what the data sheet's units scatter least on for most
plants, but a heavier pair (40 against 75, the protocol's appended heavy cycles) separates a
halved tendon far better where the stretch is a small part of the lost motion at 60 deg
(notchclutch: z 17-21 against 2-5 on development units 1-4). On planetwist the heavier pair's
units scatter more (x1.51 / 1.99 against x1.30 / 1.58: its planets take the load one after
another, a unit's own amount), and read there alone unit 2's halved strand was lost (docs/gap.md
"Session 26"). So both pairs are read, each against a sheet from the same units at the same
loads, each at half the level (two looks at one effect), and the case is named when either
clears its sheet's spread (docs/gap.md "Session 27"). Off unless :data:`HEAVY_LOADS_DEG` is set
and the protocol has those loads.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

from tsmd.gap.compliance import (
    LEVELS_DEG,
    ComplianceSheet,
    compliance_score,
    sheet_from_units,
)
from tsmd.gap.data import GapSeries
from tsmd.gap.signature import SignatureScore

HEAVY_LOADS_DEG: tuple[float, float] | None = None
"""The heavier pair of loads also read (e.g. (40, 75) with ``ProtocolDesign.heavy_amp_deg``
75); None (the default): the one pair of :data:`tsmd.gap.compliance.CONTRAST_LEVELS_DEG`."""


def sheet_at_both_loads(units: Sequence[Sequence[GapSeries]],
                        family_alpha: float = 0.05) -> ComplianceSheet | None:
    """The data sheet at the usual loads, carrying the same units' sheet at the heavier pair
    (:attr:`ComplianceSheet.heavier`) when :data:`HEAVY_LOADS_DEG` is set and both read the
    load contrast (a sheet read on the release keeps the usual pair: its premise fails there)."""
    if HEAVY_LOADS_DEG is None:
        return sheet_from_units(units, family_alpha)
    usual = sheet_from_units(units, family_alpha, LEVELS_DEG)
    if usual is None or usual.figure != "load contrast":
        return usual
    heavier = sheet_from_units(units, family_alpha, HEAVY_LOADS_DEG)
    if heavier is None or heavier.figure != "load contrast":
        return usual
    return dataclasses.replace(usual, heavier=heavier)


def either_pair_score(series: Sequence[GapSeries], sheet: Sequence[float] | ComplianceSheet,
                      n_tried: int, family_alpha: float = 0.05,
                      min_share: float = 0.05) -> SignatureScore | None:
    """:func:`tsmd.gap.compliance.compliance_score` against the sheet, and against its heavier
    pair when it has one: then each at half the level (``n_tried`` doubled) and the named one,
    else the one with the larger z."""
    if not isinstance(sheet, ComplianceSheet) or sheet.heavier is None:
        return compliance_score(series, sheet, n_tried, family_alpha, min_share)
    scores = [s for s in (compliance_score(series, sh, 2 * n_tried, family_alpha, min_share)
                          for sh in (sheet, sheet.heavier)) if s is not None]
    if not scores:
        return None
    return max(scores, key=lambda s: (s.significant, s.z))
