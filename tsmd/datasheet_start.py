"""The state the data sheet's unit is swept in: fresh from the box, or as a calibration leaves it.

Every scored unit is calibrated in the patient and tracked straight after (the benches' default
start since session 27): warmgear's shaft is warm and its slack shrunk, notchclutch's liner
soaked. Until session 28 the sheet's sweeps (omega, the reference points, the release slope, the
reference backlash and edges) ran on a fresh, cold, dry unit 0, so a product whose state moves
in its first minutes carried constants of a catheter no scored unit is: warmgear's reference
tips sat 3 deg below where the same unit's tip reaches once calibrated, while the plateau
heights are drawn through edges its calibration reads warm (session 26's ``--unit-edges``).

``calibrated``: the reference unit is characterised after the same calibration run a clinical
unit gets (the product's protocol under its sheet, motor current only), each sweep on its own
copy of the plant that run left (:mod:`tsmd.carried_plant`). Only the sweeps move; the stages
that calibrate the unit themselves start it fresh, as every unit's calibration starts.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from typing import Any

from simrig.plant import Plant
from tsmd.carried_plant import calibrate_with_plant, carried_factory
from tsmd.config import TsmdConfig
from tsmd.profile import KNOB_NAMES, DeviceKnob, DeviceModel

SHEET_STARTS = ("fresh", "calibrated")
DEFAULT_SHEET_START = "fresh"
"""The sheets shipped before session 28 were all measured on a fresh unit: the default keeps
a rerun of their commands reproducing them."""

SWEEP_FIELDS = ("omega", "reference_pos", "reference_neg", "release_omega",
                "reference_backlash_pos_deg", "reference_backlash_neg_deg",
                "dead_zone_offset_deg", "reference_dead_zone_pos_deg",
                "reference_dead_zone_neg_deg", "reference_backlash_gain",
                "backlash_settle_fraction", "backlash_release_slope_ratio",
                "reference_release_swing_A", "backlash_settle_lag_deg",
                "backlash_release_line_share", "backlash_release_local_share",
                "loaded_shape_pos", "loaded_shape_neg", "loaded_knee_pos_deg",
                "loaded_knee_neg_deg")
"""A knob's fields read from the sheet unit's +-90 deg sweeps (:func:`tsmd.datasheet.
measure_device_constants`): what ``--sweep-constants`` measures again."""


def sheet_unit_factory(start: str, factory: Callable[[], Plant], device: DeviceModel, seed: int,
                       config: TsmdConfig, log: Callable[[str], None] = print
                       ) -> Callable[[], Any]:
    """The plant factory the sheet's sweeps run on: ``factory`` itself (``fresh``), or copies of
    its unit as a calibration under ``device`` with noise seed ``seed`` left it."""
    if start not in SHEET_STARTS:
        raise ValueError(f"start must be one of {SHEET_STARTS}, got {start!r}")
    if start == "fresh":
        return factory
    t0 = time.monotonic()
    _, plant = calibrate_with_plant(device, factory, seed, config)
    log(f"  the sheet's unit calibrated under the sheet (noise seed {seed}) before its sweeps: "
        f"{time.monotonic() - t0:.0f} s")
    return carried_factory(plant)


def with_sweep_constants(device: DeviceModel, measured: DeviceModel
                         ) -> tuple[DeviceModel, list[str]]:
    """``device`` with each sweep field it carries (:data:`SWEEP_FIELDS`) as in ``measured``
    (a sheet built from a new sweep), and a line per field whose value moved. A field the sheet
    left out stays out (a stage or the schema dropped it); one the new sweep could not read
    stays as it was, said so."""
    knobs: list[DeviceKnob] = []
    lines: list[str] = []
    for name, old, new in zip(KNOB_NAMES, device.knobs, measured.knobs, strict=True):
        changes: dict[str, Any] = {}
        for field in SWEEP_FIELDS:
            before, after = getattr(old, field), getattr(new, field)
            if before is None:
                continue
            if after is None:
                lines.append(f"{name}.{field}: not read on this start, kept {_text(before)}")
                continue
            if after != before:
                changes[field] = after
                lines.append(f"{name}.{field}: {_text(before)} -> {_text(after)}")
        knobs.append(dataclasses.replace(old, **changes))
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1])), lines


def _text(value: Any) -> str:
    if isinstance(value, float) and math.isfinite(value):
        return f"{value:g}"
    knob, tip = getattr(value, "knob_deg", None), getattr(value, "tip_deg", None)
    if knob is not None and tip is not None:
        return f"({knob:g}, {tip:g})"
    return "a template" if not isinstance(value, Sequence | float | int) else str(value)


__all__ = ["DEFAULT_SHEET_START", "SHEET_STARTS", "SWEEP_FIELDS", "sheet_unit_factory",
           "with_sweep_constants"]
