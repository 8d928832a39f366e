"""The product's part of a calibration's error that no sweep narrows, measured on its sample.

A manufacturer who tracks the data sheet's unit can as well track a few more units of the same
product once (the sample: the sheet's unit and declared sample units, never a unit a customer's
figures are scored on). Each is calibrated from its current alone with the fast protocol under
the finished sheet, as every unit is, and its values are compared with its tracked tip at the
protocol's grid points (the threshold truth, :func:`tsmd.tip_truth.tip_truth`); per knob and
kind of parameter the errors the gate's own half-widths do not explain give the product's part
(:func:`tsmd.calibration.unit_part.sample_u95_deg`, session 19). The part changes only the
half-width a calibration reports, never a value, the gate or a re-sweep (session 20), so it can
be added to an existing sheet (``tsmd datasheet --update``).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

from tsmd.calibration.estimate import KINDS
from tsmd.calibration.protocol import fast_protocol
from tsmd.calibration.sample_offset import PARAMETERS, field_name, one_sided_offset_deg
from tsmd.calibration.unit_part import Z95, sample_u95_deg
from tsmd.config import TsmdConfig
from tsmd.datasheet_rule import sheet_truth
from tsmd.profile import DeviceModel
from tsmd.tracked_calibration import ProtocolRun, named_value_errors, play_protocol

Truth = dict[tuple[int, float], dict[str, float]]
"""Per (knob, other knob's angle): the tracked tip's value per parameter."""
Offsets = dict[tuple[int, str], float]
"""Per (knob, parameter): the product's one-sided miss (deg)."""
Readings = dict[tuple[int, str], tuple[list[float], list[float]]]
"""Per (knob, kind of parameter): the sample's errors against the tip and the gate's 95 %
half-widths, value by value."""

SAMPLE_KEYS = ("dead_zone_unit_u95_deg", "backlash_unit_u95_deg",
               *(field_name(name) for name in PARAMETERS))
"""The sheet's fields the sample writes (per knob); nothing else of the sheet depends on it."""


def sample_readings(runs: Sequence[tuple[ProtocolRun, Truth]],
                    offsets_deg: Offsets | None = None) -> Readings:
    """Every grid point's value minus its unit's tracked tip, less the product's one-sided
    offset of its parameter (``offsets_deg``), with the gate's half-width, over the sample's
    runs and their truths (a refused run's values count as they were read)."""
    out: Readings = {(knob, kind): ([], []) for knob in (0, 1) for kind in KINDS}
    for run, truth in runs:
        for knob, kind, name, error, est in named_value_errors(run.points, truth):
            if math.isfinite(est.u95_deg):
                out[(knob, kind)][0].append(error - (offsets_deg or {}).get((knob, name), 0.0))
                out[(knob, kind)][1].append(est.u95_deg)
    return out


def one_sided_offsets(runs: Sequence[tuple[ProtocolRun, Truth]]) -> Offsets:
    """Per knob and parameter, the product's one-sided miss over the sample's units
    (:func:`tsmd.calibration.sample_offset.one_sided_offset_deg` of each unit's mean miss);
    only the nonzero ones."""
    misses: dict[tuple[int, str], list[float]] = {}
    for run, truth in runs:
        unit: dict[tuple[int, str], list[float]] = {}
        for knob, _, name, error, _ in named_value_errors(run.points, truth):
            unit.setdefault((knob, name), []).append(error)
        for key, errors in unit.items():
            misses.setdefault(key, []).append(sum(errors) / len(errors))
    found = {key: round(one_sided_offset_deg(means), 2) for key, means in misses.items()}
    return {key: v for key, v in found.items() if v != 0.0}


def pooled(per_unit: Sequence[Readings]) -> Readings:
    """The units' readings as one sample."""
    out: Readings = {(knob, kind): ([], []) for knob in (0, 1) for kind in KINDS}
    for readings in per_unit:
        for key, (errors, gate) in readings.items():
            out[key][0].extend(errors)
            out[key][1].extend(gate)
    return out


def left_deg2(reading: tuple[list[float], list[float]]) -> float:
    """The mean square of the errors the gate's half-widths do not explain (deg^2; NaN without
    a value): what :func:`sample_u95_deg` takes the part from, so sub-samples can be pooled."""
    errors, gate = reading
    if not errors:
        return math.nan
    return sum(e * e - (g / Z95) ** 2 for e, g in zip(errors, gate, strict=True)) / len(errors)


def with_unit_parts(device: DeviceModel, readings: Readings, units: int) -> DeviceModel:
    """The sheet with each knob's product part per kind from a sample of ``units`` units (left
    out where the sample gave no value of that kind)."""
    knobs = []
    for knob, k in enumerate(device.knobs):
        dz, b = (_part(readings.get((knob, kind), ([], [])), units)
                 for kind in ("dead-zone edge", "backlash"))
        knobs.append(dataclasses.replace(k, dead_zone_unit_u95_deg=dz, backlash_unit_u95_deg=b))
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def _part(reading: tuple[list[float], list[float]], units: int) -> float | None:
    errors, gate = reading
    return round(sample_u95_deg(errors, gate, units), 2) if errors else None


def with_offsets(device: DeviceModel, offsets_deg: Offsets) -> DeviceModel:
    """The sheet with each knob's sample offsets as ``offsets_deg`` gives them (None elsewhere:
    a sheet measured again loses the offsets its new sample does not show)."""
    knobs = tuple(dataclasses.replace(
        k, sample_offset_dead_zone_pos_deg=offsets_deg.get((knob, "dead_zone_pos_deg")),
        sample_offset_dead_zone_neg_deg=offsets_deg.get((knob, "dead_zone_neg_deg")),
        sample_offset_backlash_pos_deg=offsets_deg.get((knob, "backlash_pos_deg")),
        sample_offset_backlash_neg_deg=offsets_deg.get((knob, "backlash_neg_deg")))
        for knob, k in enumerate(device.knobs))
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def measure_sample(device: DeviceModel, configs: Sequence[TsmdConfig], noise_seed: int
                   ) -> tuple[DeviceModel, list[Readings]]:
    """The sheet with the product's one-sided offsets and parts, from fast calibrations of every
    sample unit (``configs``, one sim config each) under ``device`` without its old sample
    offsets (each value as it reads); each unit's readings less the offsets."""
    bare = with_offsets(device, {})
    runs = [(play_protocol(c, bare, fast_protocol(), noise_seed), sheet_truth(c))
            for c in configs]
    offsets = one_sided_offsets(runs)
    per_unit = [sample_readings([run], offsets) for run in runs]
    return with_unit_parts(with_offsets(bare, offsets), pooled(per_unit), len(configs)), per_unit
