"""A bias of one sign on every unit of the product's sample, subtracted from reported values.

The sample (``tsmd datasheet --unit-sample``, :mod:`tsmd.datasheet_sample`) calibrates several
units of the product and compares their values with their tracked tips. Where every unit's
mean miss of one parameter has the same sign, the miss is the product's (capstan's dead-zone
edges all read 0.6-0.9 deg inside the tip, session 27), not one unit's: the units' mean is
subtracted from every unit's reported value, and the unit part (:mod:`tsmd.calibration.unit_part`)
is measured on what is left, so the reported half-width carries the scatter only.

Only the reported values move. Our compensator's fit, and the paper's compensator fed in its
frame (:mod:`tsmd.calibration.paper_frame`), read the sweeps as before: a sub-degree move of
the edges they read cost tracking on warmgear (session 26, round 2).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence

import numpy as np

from tsmd.calibration.sweep_result import SweepResult

MIN_SIGN_UNITS = 6
"""Fewest sample units whose common sign is taken as the product's: by chance, n units share a
sign with probability 2^(1-n), under 5 % from six units on (sign test, two-sided)."""

PARAMETERS = ("dead_zone_pos_deg", "dead_zone_neg_deg", "backlash_pos_deg", "backlash_neg_deg")


def field_name(name: str) -> str:
    """The data sheet's per-knob field holding parameter ``name``'s sample offset."""
    return f"sample_offset_{name}"


def one_sided_offset_deg(unit_means_deg: Sequence[float]) -> float:
    """The product's offset of one parameter from each sample unit's mean miss (value minus
    tip): their mean where at least :data:`MIN_SIGN_UNITS` units all miss on one side, else 0
    (a miss of either sign is unit-to-unit scatter, which the unit part carries)."""
    m = np.asarray([x for x in unit_means_deg if np.isfinite(x)], dtype=float)
    if m.size < MIN_SIGN_UNITS or not (np.all(m > 0.0) or np.all(m < 0.0)):
        return 0.0
    return float(np.mean(m))


def sheet_offsets_deg(knob: object) -> dict[str, float]:
    """A sheet knob's sample offsets per parameter (the nonzero ones)."""
    out = {}
    for name in PARAMETERS:
        value = getattr(knob, field_name(name), None)
        if value:
            out[name] = float(value)
    return out


def with_sample_offset(result: SweepResult, offsets_deg: Mapping[str, float]) -> SweepResult:
    """``result`` with each parameter's half-cycle values less its sample offset; a backlash
    the current does not show (``result.unseen``, the sheet's own value) is not moved."""
    values = dict(result.values)
    moved = False
    for name, shift in offsets_deg.items():
        if shift and name in values and name not in result.unseen:
            values[name] = tuple(x - shift for x in values[name])
            moved = True
    return dataclasses.replace(result, values=values) if moved else result
