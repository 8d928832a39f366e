"""Whether a product's loaded-branch templates go into its sheet, chosen on the sheet's unit.

The templates (:mod:`tsmd.compensation.loaded_shape`) are measured on every sheet's sweep but
kept only on request (``--loaded-shape``): on the family's held-out units they did not improve
ours' worst row (docs/model.md, session 10). Jawcrimp (session 22) is the other case: its tip
engages softly (the oesophagus wall and the shaft's closing coil gaps take the first 10-15 deg
of knob past the edge), so the straight line through the reference point lies 8 deg below the
tip at the edge and puts the flat 7 deg beyond it, which costs every tracking row there. Which
case a product is, the tracker on the sheet's unit says once: the unit calibrated by ``tsmd
calibrate``'s own protocol under the sheet with the templates, and on each of its sweeps the
profile's model with and without them (the straight line and its H through the same reference
point) against the tip where the model is on a loaded branch or its flat, moving outward (the
samples the level grid reads, :func:`tsmd.datasheet_level_grid.side_misses`). A knob keeps its
templates where they bring that RMS down by :data:`MIN_SHAPE_GAIN_DEG` or more.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np

from simrig.plant import Plant
from tsmd.calibration.reading_offset import reference_edge_deg
from tsmd.compensation.model_parts import model_parts
from tsmd.compensation.paper import plateau_heights
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.config import TsmdConfig
from tsmd.datasheet_level_grid import (
    NEAR_SIDE_DEG,
    SETTLE_FRACTION,
    TrackedSweep,
    tracked_sweeps,
)
from tsmd.datasheet_unit_run import calibrate_sheet_unit
from tsmd.errors import TsmdError
from tsmd.profile import DeviceModel
from tsmd.profile.device import DeviceKnob

MIN_SHAPE_GAIN_DEG = 0.5
"""The templates stay where they lower the sheet unit's loaded-branch RMS by this much (a
quarter of the 2 deg accuracy target; jawcrimp's unit 0: 3.91 -> 1.24 deg on phi1, 4.57 -> 1.87
on phi2)."""


class ShapeChoice(NamedTuple):
    """One knob's choice: the model's loaded-branch RMS (deg) straight and bent, and the verdict."""

    straight_rms_deg: float
    bent_rms_deg: float
    keep: bool


def branch_rms(sweeps: Sequence[TrackedSweep], tension: TensionPlayParams) -> float:
    """RMS of tip minus model over every sweep's samples where the model is on a loaded branch
    or its flat, moving outward (the first :data:`SETTLE_FRACTION` of a sweep left out); NaN
    without such samples."""
    errors = []
    for sweep in sweeps:
        x = np.asarray(sweep.knob_deg, dtype=float)
        tip = np.asarray(sweep.tip_deg, dtype=float)
        y, parts = model_parts(x, np.asarray(sweep.other_deg, dtype=float), tension,
                               float(tip[0]))
        a = int(len(x) * SETTLE_FRACTION)
        x, tip, y, labels = x[a:], tip[a:], y[a:], np.asarray(parts[a:])
        moving = np.sign(np.gradient(x))
        on_branch = np.isin(labels, ("loaded", "plateau"))
        for side in (1, -1):
            m = (moving == side) & on_branch & (side * x > -NEAR_SIDE_DEG)
            errors.append(tip[m] - y[m])
    e = np.concatenate(errors) if errors else np.zeros(0)
    return float(np.sqrt(np.mean(e * e))) if e.size else float("nan")


def straight(tension: TensionPlayParams, knob: DeviceKnob) -> TensionPlayParams:
    """``tension`` as the same calibration without the sheet's templates: straight lines, their
    heights through the sheet's reference points and its corrected edges (as
    :func:`tsmd.calibration.tension_play_fit.fit_tension_play` draws them)."""
    edges = [reference_edge_deg(knob.reading_offset, name, edge) for name, edge in (
        ("dead_zone_pos_deg", knob.reference_dead_zone_pos_deg),
        ("dead_zone_neg_deg", knob.reference_dead_zone_neg_deg))]
    if edges[0] is None or edges[1] is None:
        raise TsmdError("loaded-shape choice: the sheet has no reference dead-zone edges")
    h_pos, h_neg = plateau_heights(knob, edges[0], edges[1])
    return dataclasses.replace(tension, shape_pos=None, shape_neg=None, shape_grid=None,
                               sheet_loaded_knee_deg=None, height_pos_deg=h_pos,
                               height_neg_deg=h_neg, level_grid=None)


def choose_shape(sweeps: Sequence[TrackedSweep], bent: TensionPlayParams,
                 knob: DeviceKnob) -> ShapeChoice:
    """One knob's choice from the sheet unit's tracked sweeps and its profile under the
    templated sheet."""
    plain = dataclasses.replace(bent, level_grid=None)
    rms_straight = branch_rms(sweeps, straight(plain, knob))
    rms_bent = branch_rms(sweeps, plain)
    keep = bool(rms_straight - rms_bent >= MIN_SHAPE_GAIN_DEG)
    return ShapeChoice(rms_straight, rms_bent, keep)


def without_shapes(knob: DeviceKnob) -> DeviceKnob:
    """A sheet knob with no loaded-branch template, grid or knee (straight loaded lines)."""
    return dataclasses.replace(knob, loaded_shape_pos=None, loaded_shape_neg=None,
                               loaded_shape_grid=None, loaded_knee_pos_deg=None,
                               loaded_knee_neg_deg=None)


def with_shape_choice(device: DeviceModel, config: TsmdConfig, factory: Callable[[], Plant],
                      seed: int) -> DeviceModel:
    """``device`` (measured with its templates) keeping each knob's templates only where the
    sheet's unit shows them closer to its tip (:func:`choose_shape`); one line per knob."""
    t0 = time.monotonic()
    result = calibrate_sheet_unit(factory, device, "loaded-shape choice", seed, config)
    knobs = list(device.knobs)
    lines = []
    for i, (name, knob) in enumerate(zip(("phi1", "phi2"), device.knobs, strict=True)):
        tension = result.profile.knobs[i].tension_play
        if tension is None or (tension.shape_pos is None and tension.shape_neg is None):
            knobs[i] = without_shapes(knob)
            lines.append(f"{name} no curved template")
            continue
        sweeps = [s for _, s in tracked_sweeps(result, i, "loaded-shape choice")]
        choice = choose_shape(sweeps, tension, knob)
        if not choice.keep:
            knobs[i] = without_shapes(knob)
        lines.append(f"{name} straight {choice.straight_rms_deg:.2f} / bent "
                     f"{choice.bent_rms_deg:.2f} deg: {'kept' if choice.keep else 'straight'}")
    print("  loaded-branch template on the sheet's unit, RMS on its loaded branches and flats: "
          + "; ".join(lines) + f" ({time.monotonic() - t0:.0f} s)")
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))
