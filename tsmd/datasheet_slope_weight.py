"""How much of the loaded-slope change a unit's backlash-gain reading says its tip shows,
measured on the product's sample.

Each unit's omega is the sheet's times the ratio its backlash-gain readings give,
``(1 - beta_unit) / (1 - beta_sheet)`` (:mod:`tsmd.calibration.unit_slope`): all backlash taken
as rope stretch that the loaded line loses too. Where friction holds part of the backlash
(wormeyelet: the eyelets' band and the disks; session 26, docs/plant.md) a unit's gain moves
without its slope: 102 phi2 read 1.423 against its tip's 1.388, 101 phi2 1.293 against 1.37.
How far the slope follows the reading is a property of the product, not of one unit, and one
unit cannot show it (its ratio is 1 by construction). So the product's sample (the sheet's
unit and a few more, tracked once, none scored) is calibrated from current as every unit is,
each knob's tip slope tracked on a +-90 deg sweep as the sheet's was, and the least-squares
share ``w`` of the readings' move (``tip ratio - 1 = w (reading ratio - 1)``, through the sheet
unit's point: the sheet's own omega holds there) is written as ``slope_gain_weight`` (0..1).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from tsmd.calibration import calibrate
from tsmd.config import TsmdConfig
from tsmd.datasheet import analysed_from, knob_constants, settle, tip_sweep
from tsmd.profile import DeviceModel
from tsmd.replay import LockstepRunner, run_trajectory

SAMPLE_CALIBRATION_SEED = 3000
"""Noise seed of each sample unit's calibration (the tracking benches',
:data:`tsmd.bench.tracking_start.CALIBRATION_SEED`; a data-sheet stage may not import the
benchmarks, tests/test_import_graph.py)."""

MIN_READING_SPREAD = 0.01
"""Below this rms move of the readings' ratios from 1 the sample says nothing about the share
(every unit read the sheet's slope): no weight is written."""


@dataclass(frozen=True)
class SlopePair:
    """One sample unit's knob: the slope ratio its gain readings gave (its calibrated omega
    over the sheet's, without a weight) and its tracked tip's (its loaded slope over the
    sheet's omega)."""

    unit: str
    reading: float
    tip: float


def slope_weight(pairs: Sequence[SlopePair]) -> float | None:
    """The share of the readings' move from 1 the tips followed (least squares through 1,
    held within 0..1); None where the readings hardly moved (:data:`MIN_READING_SPREAD`)."""
    r = np.array([p.reading for p in pairs if math.isfinite(p.reading) and math.isfinite(p.tip)])
    t = np.array([p.tip for p in pairs if math.isfinite(p.reading) and math.isfinite(p.tip)])
    if r.size == 0 or float(np.sqrt(np.mean((r - 1.0) ** 2))) < MIN_READING_SPREAD:
        return None
    w = float(np.dot(t - 1.0, r - 1.0) / np.dot(r - 1.0, r - 1.0))
    return min(max(w, 0.0), 1.0)


def tip_slope(config: TsmdConfig, make: Callable[[], Any], knob: int, seed: int) -> float:
    """The tracked tip's loaded slope of ``knob`` (other knob at 0), read as the sheet reads
    its omega (:func:`tsmd.datasheet.knob_constants`)."""
    period_s = config.loop.period_s
    t, q, skip = settle(*tip_sweep(knob, 0.0, period_s), period_s)
    rec = run_trajectory(t, q, config=config, profile=None, method="none", seed=seed,
                         plant=make())
    return knob_constants(rec, knob, analysed_from(skip, period_s)).omega


def sample_pairs(device: DeviceModel, config: TsmdConfig, unit: str, make: Callable[[], Any],
                 seed: int) -> tuple[SlopePair, SlopePair]:
    """Both knobs' pairs of one sample unit, calibrated under ``device`` without a weight."""
    plain = dataclasses.replace(device, knobs=tuple(  # type: ignore[arg-type]
        dataclasses.replace(k, slope_gain_weight=None) for k in device.knobs))
    with LockstepRunner(None, None, "none", SAMPLE_CALIBRATION_SEED, make()) as runner:
        profile = calibrate(runner, "datasheet-slope-sample", plain)
    out = []
    for knob, k in enumerate(device.knobs):
        play = profile.knobs[knob].tension_play
        reading = math.nan if play is None else float(play.omega) / float(k.omega)
        out.append(SlopePair(unit, reading, tip_slope(config, make, knob, seed) / float(k.omega)))
    return out[0], out[1]


def with_slope_weight(device: DeviceModel, pairs: Sequence[tuple[SlopePair, SlopePair]]
                      ) -> tuple[DeviceModel, tuple[float | None, float | None]]:
    """The sheet with each knob's ``slope_gain_weight`` from its sample's pairs (left out where
    the readings did not move)."""
    weights = tuple(slope_weight([p[knob] for p in pairs]) for knob in (0, 1))
    knobs = [dataclasses.replace(k, slope_gain_weight=None if w is None else round(w, 3))
             for k, w in zip(device.knobs, weights, strict=True)]
    return (dataclasses.replace(device, knobs=(knobs[0], knobs[1])), (weights[0], weights[1]))


__all__ = ["MIN_READING_SPREAD", "SlopePair", "sample_pairs", "slope_weight", "tip_slope",
           "with_slope_weight"]
