"""The part of a calibration's error that no sweep narrows, as the product's sample shows it.

A grid point's 95 % half-width from its half-cycles' scatter (the gate's,
:class:`tsmd.calibration.estimate.Estimate`) says how sure the reading is of what the current
shows; it says nothing of how far what the current shows is from the tip. That part is the
product's: the rule's bias (a dead-zone edge read where the tendon engages, a few tenths of a
degree before the tip leaves its plateau) and the unit-to-unit part of the plant the motor
cannot feel (the sheath contacts' presliding, session 18). A manufacturer who calibrates a few
units of the product with the fast protocol and tracks their tips measures it once
(``tsmd datasheet --unit-sample``); every unit's calibration reports it in quadrature with its
own half-width (session 19).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

from tsmd.calibration.sample_offset import sheet_offsets_deg
from tsmd.calibration.sweep_result import SweepResult
from tsmd.profile.device import DeviceKnob

Z95 = 1.96
"""Two-sided 95 % of a normal spread: a gate half-width over this is its one-sigma part."""


@dataclass(frozen=True)
class UnitPart:
    """One knob's 95 % half-widths of the product's part, per kind of parameter (deg)."""

    dead_zone_u95_deg: float | None
    backlash_u95_deg: float | None
    offsets_deg: tuple[tuple[str, float], ...] = ()
    """Per parameter, the sample's one-sided miss subtracted from the reported values
    (:mod:`tsmd.calibration.sample_offset`); the half-widths above are the scatter about it."""

    @staticmethod
    def of(knob: DeviceKnob) -> UnitPart | None:
        """The sheet knob's part, None where the sheet measured neither."""
        if knob.dead_zone_unit_u95_deg is None and knob.backlash_unit_u95_deg is None:
            return None
        return UnitPart(knob.dead_zone_unit_u95_deg, knob.backlash_unit_u95_deg,
                        tuple(sheet_offsets_deg(knob).items()))

    def u95_deg(self, name: str) -> float | None:
        """The half-width for parameter ``name`` (None: not measured for its kind)."""
        return self.backlash_u95_deg if name.startswith("backlash") else self.dead_zone_u95_deg


def with_unit_part(result: SweepResult, part: UnitPart | None,
                   left_u95_deg: Mapping[str, float] | None = None) -> SweepResult:
    """``result`` carrying the product's part for every parameter the sheet measured it for;
    where the sheet has no sample part for a parameter, the bias an unapplied reading offset
    leaves in it (``left_u95_deg``, :func:`tsmd.calibration.reading_offset.left_u95_deg`) with
    the share's part in quadrature (session 27: the sample, where measured, already counts
    whatever bias the values keep). Unchanged where neither applies."""
    found: dict[str, float] = {}
    for name in result.values:
        u = part.u95_deg(name) if part is not None else None
        left = (left_u95_deg or {}).get(name, 0.0)
        if u is not None:
            found[name] = u
        elif left > 0.0 and name not in result.unseen:
            found[name] = math.hypot(result.share_u95_deg(name), left)
    if not found:
        return result
    return dataclasses.replace(result, product_u95_deg=found)


def sample_u95_deg(errors_deg: Sequence[float], gate_u95_deg: Sequence[float],
                   units: int) -> float:
    """The product's part from a sample of ``units`` units' values: each value's error against
    its tracked tip, with the gate's own 95 % half-width. Errors the gate's half-widths explain
    (each its half-width over :data:`Z95`, squared) are taken out of their mean square; what is
    left, bias and unit-to-unit part together, is the part's variance. A new unit's part is
    predicted from ``units`` draws of it (a unit's values move together: ratestate development
    unit 4's phi1 B all +2.0..+3.1 deg), so the half-width is the prediction interval's,
    t(0.975, units - 1) sqrt(1 + 1/units) sigma, not 1.96 sigma (which covered ratestate
    development units 1-4 75 % on B from a sample of four; docs/calibration.md, session 19)."""
    if units < 2:
        raise ValueError(f"a sample of {units} unit(s) says nothing of the unit-to-unit part: "
                         "give at least two")
    e = np.asarray(errors_deg, dtype=float)
    g = np.asarray(gate_u95_deg, dtype=float)
    ok = np.isfinite(e) & np.isfinite(g)
    if not ok.any():
        raise ValueError("no value with both an error and a half-width")
    left = float(np.mean(e[ok] ** 2 - (g[ok] / Z95) ** 2))
    factor = float(stats.t.ppf(0.975, units - 1)) * math.sqrt(1.0 + 1.0 / units)
    return factor * math.sqrt(max(left, 0.0))
