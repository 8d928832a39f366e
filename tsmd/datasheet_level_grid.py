"""The product's loaded level over the other knob's angle (session 21), tracked on the sheet's unit.

With the other plane bent, nitinol's tip stands further from 0 on both flats and runs short on
both loaded branches by about as much, while the current reads its edges and backlash alike
(:mod:`tsmd.compensation.level_grid`). The tracker on the sheet's unit measures that once per
product, read the way every unit uses it: the sheet's unit calibrated by ``tsmd calibrate``'s own
protocol (the tracker recording the tip alongside); on each sweep, its profile's model against
the tip where the model is on a side's loaded branch or its flat, the mean miss per side; per
other-knob angle the mean over its sweeps, less the miss at the other knob's 0 (where the sheet
read H). A shift below :data:`MIN_LEVEL_SHIFT_DEG` is taken as none (noise of one unit); a
product with none at any angle gets no field. An angle whose miss departs by more than
:data:`MAX_LEVEL_MISS_DEG` from what its neighbours on the grid say is left out: there the
calibration mis-read the unit (an edge off by tens of degrees), which is no level of the
product. A level that grows smoothly with the other knob's angle is kept however large
(pronyring's pull ring, session 26: 11-17 deg at the other knob's +-90, every angle read right).
"""

from __future__ import annotations

import dataclasses
import time
from collections import defaultdict
from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from simrig.plant import Plant
from tsmd.calibration.run import Calibration
from tsmd.compensation.level_grid import LevelGrid
from tsmd.compensation.model_parts import model_parts
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.config import TsmdConfig
from tsmd.datasheet_unit_run import calibrate_sheet_unit
from tsmd.errors import TsmdError
from tsmd.profile import DeviceModel

FloatArray = NDArray[np.float64]

MIN_LEVEL_SHIFT_DEG = 1.0
"""A side's shift below this (half the 2 deg accuracy target, as the reading offset's) is not
applied: two calibrations of nitinol's sheet unit (noise seeds 0 and 2000) read the same shift
0.4-0.7 deg apart, and lumped's unit 0 reads at most 0.77."""
MAX_LEVEL_MISS_DEG = 10.0
"""A side's miss this far from its neighbours' (:func:`misread_angles`) is a mis-read profile
there, not a level: the angle is left out of the grid (the shifts interpolate across it). With
fewer than three angles there are no neighbours to go by and the miss itself is held to it."""
SETTLE_FRACTION = 0.3
"""The first part of each sweep is left out: the knob's first loading from rest."""
NEAR_SIDE_DEG = 5.0
"""A side's samples are those beyond this far on the other side of 0 (its flat included)."""


class TrackedSweep(NamedTuple):
    """One sweep of a knob on the sheet's unit: its angle, the other knob's, the tracked tip."""

    knob_deg: FloatArray
    other_deg: FloatArray
    tip_deg: FloatArray


def side_misses(sweep: TrackedSweep, tension: TensionPlayParams) -> tuple[float, float]:
    """(positive, negative side) mean tip minus model where the model is on that side's loaded
    branch or its flat, moving outward; NaN where the sweep has too few such samples."""
    plain = dataclasses.replace(tension, level_grid=None)
    x = np.asarray(sweep.knob_deg, dtype=float)
    tip = np.asarray(sweep.tip_deg, dtype=float)
    y, parts = model_parts(x, np.asarray(sweep.other_deg, dtype=float), plain, float(tip[0]))
    a = int(len(x) * SETTLE_FRACTION)
    x, tip, y, labels = x[a:], tip[a:], y[a:], np.asarray(parts[a:])
    moving = np.sign(np.gradient(x))
    on_branch = np.isin(labels, ("loaded", "plateau"))
    out = []
    for side in (1, -1):
        m = (moving == side) & on_branch & (side * x > -NEAR_SIDE_DEG)
        out.append(float(np.mean(tip[m] - y[m])) if m.sum() > 10 else float("nan"))
    return out[0], out[1]


def misread_angles(misses: dict[float, FloatArray]) -> set[float]:
    """Grid angles whose (positive, negative side) miss departs by more than
    :data:`MAX_LEVEL_MISS_DEG` from the median of itself and its two neighbours on the grid; an
    end, judged after the inner angles, from the median of itself, the nearest inner angle kept
    and the line through the nearest two kept, carried out to it. A level the other plane's
    load sets grows smoothly over the angles, so the median follows it; one angle's mis-read
    edge stands alone. With fewer than three angles: those whose miss itself exceeds the
    limit."""
    angles = sorted(misses)
    m = np.asarray([misses[a] for a in angles], dtype=float).reshape(len(angles), -1)
    if len(angles) < 3:
        return {a for a, row in zip(angles, m, strict=True)
                if np.max(np.abs(row)) > MAX_LEVEL_MISS_DEG}

    def off(i: int, trio: FloatArray) -> bool:
        return bool(np.max(np.abs(m[i] - np.median(trio, axis=0))) > MAX_LEVEL_MISS_DEG)

    last = len(angles) - 1
    out = {i for i in range(1, last) if off(i, m[i - 1:i + 2])}
    x = np.asarray(angles, dtype=float)
    for i, inner in ((0, range(1, last + 1)), (last, range(last - 1, -1, -1))):
        kept = [j for j in inner if j not in out][:2]
        if len(kept) < 2:
            continue
        j, k = kept
        line = m[j] + (m[j] - m[k]) * (x[i] - x[j]) / (x[j] - x[k])
        if off(i, np.stack([m[i], m[j], line])):
            out.add(i)
    return {angles[i] for i in out}


def level_grid(sweeps: Sequence[tuple[float, TrackedSweep]], tension: TensionPlayParams
               ) -> LevelGrid | None:
    """The product's shifts from the sheet unit's tracked sweeps ``(other knob's grid angle,
    sweep)`` of one knob and its calibrated parameters; None where no shift reaches
    :data:`MIN_LEVEL_SHIFT_DEG` (or no sweep at the other knob's 0 to refer to)."""
    by_angle: dict[float, list[tuple[float, float]]] = defaultdict(list)
    for other, sweep in sweeps:
        by_angle[float(other)].append(side_misses(sweep, tension))
    mean = {a: np.nanmean(np.asarray(m), axis=0) for a, m in by_angle.items()}
    mean = {a: m for a, m in mean.items() if np.all(np.isfinite(m))}
    misread = misread_angles(mean)
    mean = {a: m for a, m in mean.items() if a not in misread}
    if 0.0 not in mean or len(mean) < 2:
        return None
    angles = sorted(mean)
    pos, neg = [], []
    for a in angles:
        shift = mean[a] - mean[0.0]
        pos.append(0.0 if not abs(shift[0]) >= MIN_LEVEL_SHIFT_DEG else float(shift[0]))
        neg.append(0.0 if not abs(shift[1]) >= MIN_LEVEL_SHIFT_DEG else float(shift[1]))
    if not any(pos) and not any(neg):
        return None
    return LevelGrid(tuple(angles), tuple(round(v, 2) for v in pos),
                     tuple(round(v, 2) for v in neg))


def tracked_sweeps(result: Calibration, knob: int, stage: str
                   ) -> list[tuple[float, TrackedSweep]]:
    """``(other knob's grid angle, sweep)`` of one knob from a tracked calibration of the sheet's
    unit; TsmdError naming ``stage`` where the knob has no tracked sweep."""
    mine = [p for p in result.points if p.knob == knob and p.recording is not None]
    if not mine:
        raise TsmdError(f"{stage}: no tracked sweep of knob {knob + 1}")
    sweeps = []
    for point in mine:
        rec = point.recording
        assert rec is not None
        if not rec.has_tip:
            raise TsmdError(f"{stage}: {point.name} has no tracked tip")
        sweeps.append((float(point.other_deg), TrackedSweep(
            np.asarray(rec[f"pos{knob + 1}"], float), np.asarray(rec[f"pos{2 - knob}"], float),
            np.asarray(rec[f"tip{knob + 1}"], float))))
    return sweeps


def measure_level_grids(plant_factory: Callable[[], Plant], device: DeviceModel,
                        seed: int = 2000, config: TsmdConfig | None = None
                        ) -> tuple[LevelGrid | None, LevelGrid | None]:
    """Both knobs' grids, from one tracked calibration of the sheet's unit with ``device``."""
    result = calibrate_sheet_unit(plant_factory, device, "level grid", seed, config)
    grids: list[LevelGrid | None] = []
    for knob in (0, 1):
        tension = result.profile.knobs[knob].tension_play
        if tension is None:
            raise TsmdError(f"level grid: no tracked sweep of knob {knob + 1}")
        grids.append(level_grid(tracked_sweeps(result, knob, "level grid"), tension))
    return grids[0], grids[1]


def with_level_grid(device: DeviceModel, config: TsmdConfig, factory: Callable[[], Plant],
                    seed: int) -> DeviceModel:
    """The sheet with each knob's ``loaded_level_grid`` where the sheet's unit shows one."""
    t0 = time.monotonic()
    grids = measure_level_grids(factory, device, seed, config)
    knobs = tuple(dataclasses.replace(k, loaded_level_grid=g)
                  for k, g in zip(device.knobs, grids, strict=True))
    print("  loaded level over the other knob, pos / neg deg: " + "; ".join(
        f"{n} " + ("none" if g is None else ", ".join(
            f"{a:+.0f}: {p:+.2f} / {q:+.2f}"
            for a, p, q in zip(g.other_knob_deg, g.pos_deg, g.neg_deg, strict=True)))
        for n, g in zip(("phi1", "phi2"), grids, strict=True))
          + f" ({time.monotonic() - t0:.0f} s)")
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))
