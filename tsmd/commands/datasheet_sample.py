"""`tsmd datasheet`'s sample: its unit list and its part on a sheet (measured with the sheet, or
added by ``--update FILE``, :mod:`tsmd.commands.datasheet_update`).

The part only widens the half-width a calibration reports (never a value, the gate or a
re-sweep: :class:`tsmd.calibration.estimate.Estimate`), so a shipped sheet can carry it without
being re-measured; its sample is calibrated under exactly that sheet (docs/calibration.md,
session 20).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import re
import time
from typing import Any

from simrig.family import DEVELOPMENT_UNITS, HELD_OUT_UNITS
from simrig.plant import load_plant
from tsmd.calibration.sample_offset import sheet_offsets_deg
from tsmd.config import TsmdConfig
from tsmd.datasheet import DatasheetError
from tsmd.datasheet_sample import left_deg2, measure_sample
from tsmd.datasheet_slope_weight import sample_pairs, with_slope_weight
from tsmd.profile import DeviceModel

SCORED_UNITS = frozenset(DEVELOPMENT_UNITS + HELD_OUT_UNITS)
"""Units a figure is scored on (development and held out): never in a product's sample."""

def sample_units(text: str, own_unit: object) -> list[int]:
    """``--unit-sample``: units and ranges (``201-208``), none scored, none twice, not the
    sheet's own unit (``own_unit``, always in the sample)."""
    units: list[int] = []
    for x in (x.strip() for x in text.split(",") if x.strip()):
        m = re.fullmatch(r"(\d+)(?:-(\d+))?", x)
        if m is None:
            raise DatasheetError(f"--unit-sample: not a comma-separated list of units or "
                                 f"ranges (201-208): {text!r}")
        last = int(m[2] if m[2] is not None else m[1])
        if last < int(m[1]):
            raise DatasheetError(f"--unit-sample: range {x} runs backwards")
        units += range(int(m[1]), last + 1)
    if not units:
        raise DatasheetError("--unit-sample: give at least one unit")
    scored = sorted(set(units) & SCORED_UNITS)
    if scored:
        raise DatasheetError(f"--unit-sample: unit(s) {','.join(map(str, scored))} are scored "
                             f"(development 1-8, held out 101-108); a sample never holds one")
    if len(set(units)) < len(units) or own_unit in units:
        raise DatasheetError("--unit-sample: a unit twice (the sheet's own unit is always in "
                             "the sample)")
    return units


def with_sample(device: DeviceModel, config: TsmdConfig, plant: str, params: dict[str, Any],
                unit_key: str, units: list[int], seed: int) -> DeviceModel:
    """The sheet with the product's parts of the error no sweep narrows, from its sample; each
    unit's mean square beyond the gate printed, so a sub-sample's part can be pooled again."""
    t0 = time.monotonic()
    configs = [config.replace(sim=dataclasses.replace(config.sim, plant=plant, params=p))
               for p in [params, *({**params, unit_key: u} for u in units)]]
    device, per_unit = measure_sample(device, configs, seed)
    kinds = (("D", "dead-zone edge"), ("B", "backlash"))
    for c, readings in zip(configs, per_unit, strict=True):
        print(f"  sample unit {c.sim.params.get(unit_key, 'sheet')}: " + "; ".join(
            f"{name} " + ", ".join(
                f"{short} {len(readings[(knob, kind)][0])} values, left "
                f"{_or_none(left_deg2(readings[(knob, kind)]), 3)} deg^2" for short, kind in kinds)
            for knob, name in enumerate(("phi1", "phi2"))))
    for knob, (name, k) in enumerate(zip(("phi1", "phi2"), device.knobs, strict=True)):
        n = [sum(len(r[(knob, kind)][0]) for r in per_unit) for _, kind in kinds]
        print(f"{name} unit part on the sample ({len(configs)} units, noise seed {seed}): D "
              f"{_or_none(k.dead_zone_unit_u95_deg, 2)} deg over {n[0]} values, B "
              f"{_or_none(k.backlash_unit_u95_deg, 2)} deg over {n[1]}")
        offsets = sheet_offsets_deg(k)
        print(f"{name} one-sided misses subtracted (every sample unit's on one side): "
              + (", ".join(f"{p} {v:+.2f} deg" for p, v in offsets.items()) or "none"))
    print(f"  sample: {time.monotonic() - t0:.0f} s")
    return device


def with_slope_sample(device: DeviceModel, config: TsmdConfig, plant: str,
                      params: dict[str, Any], unit_key: str, units: list[int], seed: int
                      ) -> DeviceModel:
    """The sheet with each knob's ``slope_gain_weight`` from the sheet's unit and ``units``
    (each pair printed, so the choice can be checked by hand)."""
    t0 = time.monotonic()
    pairs = []
    for p in [params, *({**params, unit_key: u} for u in units)]:
        pairs.append(sample_pairs(device, config, str(p.get(unit_key, "sheet")),
                                  functools.partial(load_plant, plant, p), seed))
        print(f"  slope sample unit {pairs[-1][0].unit}: " + "; ".join(
            f"{name} reading {q.reading:.3f} tip {q.tip:.3f}"
            for name, q in zip(("phi1", "phi2"), pairs[-1], strict=True)), flush=True)
    device, weights = with_slope_weight(device, pairs)
    for name, w in zip(("phi1", "phi2"), weights, strict=True):
        print(f"{name} slope_gain_weight on the sample ({len(pairs)} units, noise seed {seed}): "
              f"{_or_none(w, 3)}")
    print(f"  slope sample: {time.monotonic() - t0:.0f} s")
    return device


def _or_none(value: float | None, decimals: int) -> str:
    return "none" if value is None or not math.isfinite(value) else f"{value:.{decimals}f}"
