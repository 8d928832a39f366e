"""The product's release per reversal, read from the data-sheet unit's tip against its model
and kept where it tracks better there (session 23, ``tsmd datasheet --release-end-shape``).

The sheet's unit is calibrated once (paper protocol). Each knob is then swept +-A (0.04 Hz,
other knob at 0, no compensation) at each of :data:`AMPLITUDES_DEG`; on every release pass
(mirrored to the positive side) the line through 20-80 % of the drop from the reversal to the
far plateau gives a slope and an end (where it meets the plateau), read alike on the tip and on
the unit's static model (its current's release line) fed the same knob angles. Their ratios per
amplitude are the product's shape (:class:`tsmd.compensation.reversal_release.ReleaseEndShape`);
each unit applies them to its own static line. The unit's tip is then tracked through the
paper's quick 1-DOF rows of each knob with the release line per reversal and without (the same
profile, the field removed), and the shape written on a knob only where it lowers the mean RMSE
by :data:`tsmd.datasheet_ratio_gain.MIN_RMSE_GAIN`.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from simrig.analysis import split_passes
from simrig.plant import Plant
from tsmd.compensation.model_parts import model_parts
from tsmd.compensation.reversal_release import (
    END_RATIO_RANGE,
    REFERENCE_REVERSAL_DEG,
    SLOPE_RATIO_RANGE,
    ReleaseEndShape,
)
from tsmd.config import TsmdConfig
from tsmd.datasheet import settle
from tsmd.datasheet_amplitude import amplitude_sweep
from tsmd.datasheet_ratio_gain import MIN_RMSE_GAIN, knob_rows, track_rmse_deg
from tsmd.datasheet_unit_run import SHEET_UNIT_SEED, calibrate_sheet_unit
from tsmd.profile import CatheterProfile, DeviceModel
from tsmd.replay import run_trajectory
from tsmd.tracking_scenarios import scenarios

FloatArray = NDArray[np.float64]
AMPLITUDES_DEG: tuple[float, ...] = (45.0, 60.0, 75.0, 90.0)
"""The sweeps' amplitudes: the tracking rows reverse at 45-60 deg, the calibration at 90."""
FLAT_WINDOW_DEG = 5.0
"""The far plateau's level: the tip's median while the knob is within this of 0."""
DROP_SHARE: tuple[float, float] = (0.2, 0.8)
"""The part of the release drop the tip's line is fitted through (clear of both corners)."""
MIN_SAMPLES = 10


def pass_release_line(x_deg: FloatArray, tip_deg: FloatArray) -> tuple[float, float] | None:
    """One release pass's line (end on the far plateau in knob deg, slope), the pass mirrored
    so that it starts at its positive reversal; None where the pass shows no release."""
    near = np.abs(x_deg) < FLAT_WINDOW_DEG
    if near.sum() < MIN_SAMPLES // 2:
        return None
    flat = float(np.median(tip_deg[near]))
    drop = tip_deg[0] - tip_deg
    total = tip_deg[0] - flat
    if not total > 1.0:
        return None
    sel = (drop > DROP_SHARE[0] * total) & (drop < DROP_SHARE[1] * total) & (x_deg > 0.0)
    if sel.sum() < MIN_SAMPLES:
        return None
    slope, intercept = np.polyfit(x_deg[sel], tip_deg[sel], 1)
    return None if not slope > 0.0 else (float((flat - intercept) / slope), float(slope))


def sweep_release_line(pos_deg: FloatArray, out_deg: FloatArray, amplitude_deg: float
                       ) -> tuple[float, float] | None:
    """The median release end and slope over a sweep's passes that start at its amplitude."""
    lines = []
    for s, e, d in split_passes(pos_deg):
        x, y = -d * pos_deg[s:e], -d * out_deg[s:e]
        if x.size and x[0] >= amplitude_deg - 1.0:
            line = pass_release_line(x, y)
            if line is not None:
                lines.append(line)
    if not lines:
        return None
    end, slope = np.median(np.array(lines), axis=0)
    return float(end), float(slope)


Line = tuple[float, float] | None


def shape_from_lines(tip: dict[float, Line], model: dict[float, Line]) -> ReleaseEndShape | None:
    """The shape from the tip's and the model's release line per amplitude (ratios outside
    the plausible ranges left out); None with no usable amplitude."""
    knots = []
    for amp in sorted(tip):
        t, m = tip[amp], model.get(amp)
        if t is None or m is None or not m[0] > 0.0:
            continue
        end, slope = t[0] / m[0], t[1] / m[1]
        if (END_RATIO_RANGE[0] <= end <= END_RATIO_RANGE[1]
                and SLOPE_RATIO_RANGE[0] <= slope <= SLOPE_RATIO_RANGE[1]):
            knots.append((amp / REFERENCE_REVERSAL_DEG, end, slope))
    if not knots:
        return None
    return ReleaseEndShape(*(tuple(k[i] for k in knots) for i in range(3)))


def measure_release_lines(plant_factory: Callable[[], Plant], profile: CatheterProfile,
                          knob: int, seed: int, config: TsmdConfig
                          ) -> tuple[dict[float, Line], dict[float, Line]]:
    """One knob's release line per amplitude on the sheet's unit: its tip's, its model's."""
    period_s = config.loop.period_s
    params = profile.knobs[knob].tension_play
    tip: dict[float, Line] = {}
    model: dict[float, Line] = {}
    for amp in AMPLITUDES_DEG:
        t, q, skip = settle(*amplitude_sweep(knob, amp, period_s), period_s)
        rec = run_trajectory(t, q, config=config, profile=None, method="none", seed=seed,
                             plant=plant_factory())
        start = skip + round(1.0 / 0.04 / period_s)  # after the conditioning cycle
        pos = np.asarray(rec[f"pos{knob + 1}"], float)[start:]  # what the catheter saw
        tip[amp] = sweep_release_line(pos, np.asarray(rec[f"tip{knob + 1}"], float)[start:],
                                      amp)
        if params is not None:
            y, _ = model_parts(pos, np.asarray(rec[f"pos{2 - knob}"], float)[start:],
                               dataclasses.replace(params, release_end=None), 0.0)
            model[amp] = sweep_release_line(pos, y, amp)
    return tip, model


def with_shapes(profile: CatheterProfile, shapes: Sequence[ReleaseEndShape | None]
                ) -> CatheterProfile:
    """The profile with each knob's release shape as given (None: the static lines)."""
    knobs = list(profile.knobs)
    for i, shape in enumerate(shapes):
        tp = knobs[i].tension_play
        if tp is not None:
            knobs[i] = dataclasses.replace(
                knobs[i], tension_play=dataclasses.replace(tp, release_end=shape))
    return dataclasses.replace(profile, knobs=(knobs[0], knobs[1]))


def _fmt(lines: dict[float, Line]) -> str:
    return ", ".join("-" if v is None else f"{v[0]:.1f}/{v[1]:.2f}" for v in lines.values())


def with_release_end(device: DeviceModel, config: TsmdConfig, factory: Callable[[], Plant],
                     seed: int = SHEET_UNIT_SEED) -> DeviceModel:
    """The sheet with each knob's ``release_end_shape`` where the sheet unit's tip shows one
    and tracking on that unit prefers it; printed per knob."""
    t0 = time.monotonic()
    bare = [dataclasses.replace(k, release_end_shape=None) for k in device.knobs]
    device = dataclasses.replace(device, knobs=(bare[0], bare[1]))
    profile = with_shapes(calibrate_sheet_unit(factory, device, "release end", seed,
                                               config).profile, (None, None))
    quick = scenarios(quick=True)
    knobs = list(device.knobs)
    parts = []
    for i in (0, 1):
        tip, model = measure_release_lines(factory, profile, i, seed, config)
        shape = shape_from_lines(tip, model)
        read = f"phi{i + 1} end/slope tip {_fmt(tip)}, model {_fmt(model)}"
        if shape is None:
            parts.append(f"{read}: no shape")
            continue
        rows = knob_rows(i, quick)
        trial = with_shapes(profile, [shape if j == i else None for j in (0, 1)])
        with_deg = float(np.mean([track_rmse_deg(s, trial, factory, config) for s in rows]))
        without_deg = float(np.mean([track_rmse_deg(s, profile, factory, config)
                                     for s in rows]))
        keep = with_deg < (1.0 - MIN_RMSE_GAIN) * without_deg
        if keep:
            knobs[i] = dataclasses.replace(knobs[i], release_end_shape=shape)
        parts.append(f"{read}; RMSE with {with_deg:.3f} / without {without_deg:.3f} deg -> "
                     + ("written" if keep else "not written"))
    print(f"  release per reversal (sheet unit's tip against its model, amplitudes "
          f"{'/'.join(f'{a:g}' for a in AMPLITUDES_DEG)} deg): " + "; ".join(parts)
          + f" ({time.monotonic() - t0:.0f} s)")
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))
