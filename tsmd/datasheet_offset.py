"""The product's reading offset, measured on the data sheet's tracked unit (session 14).

The sheet's unit is calibrated with the fast protocol from its current alone, as every unit is,
with the sheet's chosen rules; each half-cycle's D and B minus the tracked tip's (the threshold
truth, :func:`tsmd.tip_truth.tip_truth`) at the same grid point is one reading of the product's
offset there. Per parameter and other-knob angle the offset is their robust mean with a 95 %
half-width pooled as a calibration pools its own half-cycles
(:func:`tsmd.calibration.estimate.point_estimates`): the sheet says how sure it is, the
calibration decides what to apply (:mod:`tsmd.calibration.reading_offset`).

Session 20: a dead-zone edge whose threshold reading on the sheet unit's tip moves by more than
the 2 deg target when the tip carries the tracker's noise is no product's edge: the tip creeps
along its plateau by about the threshold (archwave's tensioners), and whether the reading lands
on the knee or 10-17 deg inside it depends on the creep's faint curvature, which changes from
unit to unit with state the motor cannot feel. An offset to it would carry unit 0's draw to
every unit, so its readings are left out (:func:`noise_bound_edges`).
"""

from __future__ import annotations

import dataclasses
import math
from collections import defaultdict
from collections.abc import Sequence

import numpy as np

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.estimate import point_estimates
from tsmd.calibration.protocol import fast_protocol
from tsmd.calibration.sweep_result import PARAMETERS, SweepResult
from tsmd.config import TsmdConfig
from tsmd.datasheet_offset_help import helpful_offset
from tsmd.datasheet_rule import Truth
from tsmd.profile import DeviceModel
from tsmd.profile.reading_offset import OffsetGrid, ReadingOffset
from tsmd.tip_truth import tip_truth
from tsmd.tracked_calibration import TARGET_DEG, ProtocolRun, play_protocol, truth_sweeps

EDGES = ("dead_zone_pos_deg", "dead_zone_neg_deg")
EDGE_NOISE_DRAWS = 3
"""Noise draws the sheet unit's edges are re-read with (seeds 0-2: the sheet is reproducible)."""

Unsure = set[tuple[int, float, str]]
"""(knob, other-knob angle, parameter) whose reading on the sheet unit is no product's."""


def noise_bound_edges(points: Sequence[GridPoint], tip_noise_deg: float) -> Unsure:
    """The dead-zone edges whose threshold reading on these sweeps' tip spreads by more than
    ``TARGET_DEG`` over the noise-free tip and :data:`EDGE_NOISE_DRAWS` draws of the tracker's
    noise (none without noise)."""
    out: Unsure = set()
    if not tip_noise_deg > 0.0:
        return out
    for p in points:
        reads = [tip_truth(p)] + [tip_truth(p, tip_noise_deg=tip_noise_deg, noise_seed=s)
                                  for s in range(EDGE_NOISE_DRAWS)]
        for name in EDGES:
            v = np.array([r.get(name, math.nan) for r in reads])
            if np.all(np.isfinite(v)) and float(np.ptp(v)) > TARGET_DEG:
                out.add((p.knob, float(p.other_deg), name))
    return out


def offset_readings(runs: Sequence[ProtocolRun], truth: Truth,
                    parameters: Sequence[str] = PARAMETERS, skip_unseen: bool = False,
                    unsure: Unsure | None = None
                    ) -> dict[tuple[int, float], dict[str, list[float]]]:
    """Per (knob, other-knob angle): each parameter's half-cycle values minus the tip's, over
    every run (refused runs count too: their values are read the same way); ``skip_unseen``
    leaves out values that are the sheet's fallback, not a reading (``SweepResult.unseen``),
    ``unsure`` the tip readings that are no product's (:func:`noise_bound_edges`)."""
    out: dict[tuple[int, float], dict[str, list[float]]] = defaultdict(
        lambda: defaultdict(list))
    for run in runs:
        for p in run.points:
            tip = truth.get((p.knob, float(p.other_deg)))
            if tip is None:
                continue
            for name in parameters:
                if skip_unseen and name in p.result.unseen:
                    continue
                if unsure and (p.knob, float(p.other_deg), name) in unsure:
                    continue
                ref = tip.get(name, math.nan)
                out[(p.knob, float(p.other_deg))][name] += [
                    v - ref for v in p.result.values.get(name, ()) if math.isfinite(v - ref)]
    return out


def reading_offsets(readings: dict[tuple[int, float], dict[str, list[float]]]
                    ) -> tuple[ReadingOffset | None, ReadingOffset | None]:
    """Each knob's offset grid from :func:`offset_readings` (None for a knob without readings
    at every one of its angles)."""
    keys = sorted(readings)
    results = [SweepResult(None, (), {n: tuple(readings[k][n]) for n in PARAMETERS})  # type: ignore[arg-type]
               for k in keys]
    estimates = dict(zip(keys, point_estimates(results), strict=True))
    knobs: list[ReadingOffset | None] = []
    for knob in (0, 1):
        mine = [k for k in keys if k[0] == knob]
        grids = []
        for name in PARAMETERS:
            es = [estimates[k][name] for k in mine]
            if not es or any(e.n == 0 or not math.isfinite(e.u95_deg) for e in es):
                continue
            grids.append((name, OffsetGrid(tuple(round(e.value, 2) for e in es),
                                           tuple(round(e.u95_deg, 2) for e in es),
                                           tuple(e.n for e in es))))
        knobs.append(ReadingOffset(tuple(k[1] for k in mine), tuple(grids))
                     if mine and grids else None)
    return knobs[0], knobs[1]


def without_offset(device: DeviceModel) -> DeviceModel:
    knobs = tuple(dataclasses.replace(k, reading_offset=None) for k in device.knobs)
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def with_reading_offset(device: DeviceModel, config: TsmdConfig, truth: Truth,
                        noise_seeds: Sequence[int],
                        truth_points: Sequence[GridPoint] | None = None,
                        made: tuple[DeviceModel, Sequence[ProtocolRun]] | None = None
                        ) -> tuple[DeviceModel, list[ProtocolRun]]:
    """The sheet with each knob's reading offset, from fast calibrations of its own unit
    (``config.sim``) with the sheet as chosen (no offset applied while measuring it); a knob's
    dead-zone edge gets none where the tip's reading of it is bound to the tracker's noise
    (:func:`noise_bound_edges`, on the sweeps the truth is read from: ``truth_points``, or
    swept again when not given). ``made``: a sheet and its unit's fast calibrations already run
    with it, one per noise seed (the edge-curve choice's), re-used where that sheet is the one
    measured here. A backlash offset is written where it lowers those readings' mean absolute
    error, else 0 (:mod:`tsmd.datasheet_offset_help`)."""
    plain = without_offset(device)
    if made is not None and made[0] == plain and len(made[1]) == len(noise_seeds):
        runs = list(made[1])
    else:
        runs = [play_protocol(config, plain, fast_protocol(), seed) for seed in noise_seeds]
    points = truth_sweeps(config) if truth_points is None else truth_points
    unsure = noise_bound_edges(points, config.sim.tracker_noise_deg)
    readings = offset_readings(runs, truth, unsure=unsure)
    offsets = reading_offsets(readings)
    # a backlash offset only where it helps the readings it came from (session 22)
    knobs = tuple(dataclasses.replace(k, reading_offset=helpful_offset(o, knob, readings))
                  for knob, (k, o) in enumerate(zip(plain.knobs, offsets, strict=True)))
    return dataclasses.replace(plain, knobs=(knobs[0], knobs[1])), runs
