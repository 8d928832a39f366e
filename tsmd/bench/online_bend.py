"""The product's bend relation for `tsmd bench online`: the data sheet's, measured on the
family's nominal unit where the sheet has none.

A manufacturer measures it once on the data sheet's unit (unit 0, never scored), calibrated
straight and after sheath bends of 30, 60 and 90 deg (`tsmd datasheet --bend-relation`,
:mod:`tsmd.datasheet_bend`); the daemon's online worker reads it from the sheet. The bench's
sheets (the capstan product's built-in one, the measured lumped one, the session-11 sheets of
the others) carry none, so the bench measures it the same way from unit 0's cached
calibrations.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tsmd.bench.online_units import calibrated, shape_change
from tsmd.datasheet_bend import bend_relation
from tsmd.online.bend import BendRelation, sheet_bend_relation

SHEET_UNIT = 0


def product_bend_relation(plant: str, device: Any, cache: Path) -> BendRelation:
    """The sheet's relation, or (none on the sheet) the one unit 0's cached calibrations give
    (made when missing)."""
    on_sheet = sheet_bend_relation(device)
    if on_sheet is not None:
        return on_sheet

    def unit0(bend_deg: float) -> Any:
        if not bend_deg:
            return calibrated(plant, SHEET_UNIT, None, device, cache, "straight")
        return calibrated(plant, SHEET_UNIT, shape_change(f"curvature:{bend_deg:g}"), device,
                          cache, f"curvature-{bend_deg:g}")

    return bend_relation(unit0)


__all__ = ["product_bend_relation"]
