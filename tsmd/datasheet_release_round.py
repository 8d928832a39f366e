"""The product's rounded release (session 20), tracked on the sheet's unit.

Method ours holds the backlash the current reads after a reversal, then falls on its release
line. On nitinol the tip leaves that hold gradually and its straight release lies later: the
sharp corner missed the tip's fall by 2.1-2.2 deg rms on the sheet's unit (3.1-4.6 on development
unit 1), a parabola of half-width 0.70-0.85 B with the line 0.15-0.20 B later by 0.9-1.0
(:mod:`tsmd.compensation.release_round`; B the unit's backlash at a 90 deg reversal, as its
current reads it; docs/model.md "Session 20"). The tracker on the sheet's unit measures that
shape once per product, read the way every unit uses it: the sheet's unit calibrated by
``tsmd calibrate``'s own protocol (the tracker recording the tip alongside), its profile's hold
and release line against the tip's fall on the sweep with the other knob at 0, from each
reversal to :data:`WINDOW_END_DEG` from 0, over a grid of (shift, round). A product whose best
pair gains less than :data:`MIN_GAIN_DEG` over the sharp corner gets none (the corner stays
sharp).
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from simrig.plant import Plant
from tsmd.calibration.identify import split_half_cycles
from tsmd.calibration.signal import lowpass
from tsmd.compensation.release_round import reference_backlash_deg
from tsmd.compensation.tension_play import release_slope
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.config import TsmdConfig
from tsmd.datasheet_unit_run import calibrate_sheet_unit
from tsmd.errors import TsmdError
from tsmd.profile import DeviceModel

FloatArray = NDArray[np.float64]

SHIFT_GRID: tuple[float, ...] = tuple(round(-0.3 + 0.05 * i, 2) for i in range(19))
"""Release-line shifts tried, in reference backlashes (-0.3 .. 0.6)."""
ROUND_GRID: tuple[float, ...] = tuple(round(0.05 * i, 2) for i in range(21))
"""Half-widths tried, in reference backlashes (0 .. 1)."""
WINDOW_END_DEG = 40.0
"""The fall is scored from the reversal to this far from 0 (the release, not the far side)."""
MIN_GAIN_DEG = 0.3
"""A rounding that fits the tip's fall less than this much better (rms) is not worth a field."""
_MIN_REVERSAL_DEG = 10.0


def release_drop_deg(travel_deg: FloatArray, corner_deg: float, half_width_deg: float,
                     slope: float) -> FloatArray:
    """The model's fall after ``travel_deg`` of knob travel back from a reversal: held until the
    rounding, a parabola of ``half_width_deg`` centred on the corner, then the release line."""
    if half_width_deg <= 0.0:
        return np.asarray(slope * np.maximum(travel_deg - corner_deg, 0.0), dtype=float)
    lo, hi = corner_deg - half_width_deg, corner_deg + half_width_deg
    inside = slope * (travel_deg - lo) ** 2 / (4.0 * half_width_deg)
    return np.asarray(np.where(travel_deg <= lo, 0.0, np.where(
        travel_deg >= hi, slope * (travel_deg - corner_deg), inside)), dtype=float)


def fit_release_round(pos_deg: FloatArray, tip_deg: FloatArray, sample_rate_hz: float,
                      tension: TensionPlayParams) -> tuple[float, float, float, float] | None:
    """(shift, round, rms sharp, rms best) over the grids for one knob's sweep (knob position
    and tracked tip) and its calibrated parameters at the other knob's 0; None: no release."""
    i = int(np.argmin(np.abs(np.asarray(tension.other_knob_deg))))
    tip, _ = lowpass(np.asarray(tip_deg, float), sample_rate_hz)
    x = np.asarray(pos_deg, float)
    sq = np.zeros((len(SHIFT_GRID), len(ROUND_GRID)))
    n = 0
    for direction, a, b, _ in split_half_cycles(x, _MIN_REVERSAL_DEG):
        side = -direction  # the side released: falling from +A is direction -1
        if a == 0 or b - a < 50:
            continue
        beta, x0 = ((tension.backlash_gain_pos[i], tension.zero_load_pos_deg[i]) if side > 0
                    else (tension.backlash_gain_neg[i], tension.zero_load_neg_deg[i]))
        backlash = abs(beta * (x[a] - x0))
        b_ref = reference_backlash_deg(beta, x0, side)
        slope = release_slope(tension.omega, beta)
        xs, ts = x[a:b], tip[a:b]
        keep = side * xs >= WINDOW_END_DEG
        travel = side * (x[a] - xs)
        for si, shift in enumerate(SHIFT_GRID):
            for ri, rnd in enumerate(ROUND_GRID):
                model = tip[a] - side * release_drop_deg(travel, backlash + shift * b_ref,
                                                         rnd * b_ref, slope)
                sq[si, ri] += float(np.sum((model - ts)[keep] ** 2))
        n += int(keep.sum())
    if n == 0:
        return None
    rms = np.sqrt(sq / n)
    si, ri = (int(v) for v in np.unravel_index(int(np.argmin(rms)), rms.shape))
    sharp = float(rms[SHIFT_GRID.index(0.0), 0])
    best = float(rms[si, ri])
    return (SHIFT_GRID[si], ROUND_GRID[ri], sharp, best) if math.isfinite(best) else None


def measure_release_round(plant_factory: Callable[[], Plant], device: DeviceModel,
                          seed: int = 2000, config: TsmdConfig | None = None
                          ) -> tuple[tuple[float, float, float, float] | None, ...]:
    """Both knobs' fit, from one tracked calibration of the sheet's unit with ``device``."""
    result = calibrate_sheet_unit(plant_factory, device, "release round", seed, config)
    fits: list[tuple[float, float, float, float] | None] = []
    for knob in (0, 1):
        tension = result.profile.knobs[knob].tension_play
        mine = [p for p in result.points if p.knob == knob and p.recording is not None]
        if tension is None or not mine:
            raise TsmdError(f"release round: no tracked sweep of knob {knob + 1}")
        point = min(mine, key=lambda p: abs(p.other_deg))
        rec = point.recording
        assert rec is not None
        if not rec.has_tip:
            raise TsmdError(f"release round: {point.name} has no tracked tip")
        t = np.asarray(rec["t"], float)
        fits.append(fit_release_round(np.asarray(rec[f"pos{knob + 1}"], float),
                                      np.asarray(rec[f"tip{knob + 1}"], float),
                                      1.0 / float(np.median(np.diff(t))), tension))
    return tuple(fits)


def worth_a_field(fit: tuple[float, float, float, float] | None) -> bool:
    """The pair fits the tip's fall by at least :data:`MIN_GAIN_DEG` better than sharp."""
    return fit is not None and fit[2] - fit[3] >= MIN_GAIN_DEG


def with_release_round(device: DeviceModel, config: TsmdConfig, factory: Callable[[], Plant],
                       seed: int) -> DeviceModel:
    """The sheet with each knob's ``release_round`` / ``release_shift`` where worth a field
    (a knob that is not keeps none: a sharp corner)."""
    t0 = time.monotonic()
    fits = measure_release_round(factory, device, seed, config)
    knobs = tuple(dataclasses.replace(k, release_shift=f[0], release_round=f[1])
                  if f is not None and worth_a_field(f)
                  else dataclasses.replace(k, release_shift=None, release_round=None)
                  for k, f in zip(device.knobs, fits, strict=True))
    print("  release round, shift / round (rms sharp -> rounded): " + ", ".join(
        f"{n} {'none' if f is None else f'{f[0]:+.2f} / {f[1]:.2f} ({f[2]:.2f} -> {f[3]:.2f} deg)'}"
        for n, f in zip(("phi1", "phi2"), fits, strict=True))
          + f" ({time.monotonic() - t0:.0f} s)")
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))
