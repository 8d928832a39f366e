"""The product's bend relation for `tsmd bench online`, measured on the family's nominal unit.

A manufacturer measures it once on the data sheet's unit (unit 0, never scored): calibrated
straight and after sheath bends of 30, 60 and 90 deg (:func:`tsmd.online.bend.
measure_bend_relation`); the online estimator then applies it to other units of the product.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tsmd.bench.online_units import calibrated, shape_change
from tsmd.calibration.errors import CalibrationRefusedError
from tsmd.online.bend import BendRelation, measure_bend_relation

BENDS_DEG = (30.0, 60.0, 90.0)
SHEET_UNIT = 0


def product_bend_relation(plant: str, device: Any, cache: Path) -> BendRelation:
    """The relation from unit 0's cached calibrations (made when missing); a bend whose
    calibration is refused is left out."""
    straight = calibrated(plant, SHEET_UNIT, None, device, cache, "straight")
    bent = []
    for deg in BENDS_DEG:
        try:
            bent.append(calibrated(plant, SHEET_UNIT, shape_change(f"curvature:{deg:g}"),
                                   device, cache, f"curvature-{deg:g}"))
        except CalibrationRefusedError:
            continue
    return measure_bend_relation(straight, bent)


__all__ = ["BENDS_DEG", "product_bend_relation"]
