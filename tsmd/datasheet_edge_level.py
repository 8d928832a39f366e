"""The product's edge-level share (session 23), tracked on the data sheet's unit.

How far the tip's loaded level follows the edge the current reads as the other knob turns
(:mod:`tsmd.calibration.edge_level`) is the product's: the tracker on the sheet's unit measures
it once. The unit is calibrated by ``tsmd calibrate``'s own protocol under the sheet; on each
sweep its profile's model (no level grid) against the tip, the mean miss per side where the
model is on that side's loaded branch or its flat, moving outward
(:func:`tsmd.datasheet_level_grid.side_misses`); per other-knob angle the mean over its sweeps,
less the miss at the other knob's 0. Against each angle's edge move ``omega (D(a) - D(0))`` of
the same profile, the least-squares share through 0 of both sides together. A knob keeps it
where it brings the misses' RMS down by :data:`MIN_EDGE_LEVEL_GAIN_DEG` and lies in
:data:`~tsmd.compensation.level_grid.EDGE_LEVEL_SHARE_RANGE`.
"""

from __future__ import annotations

import dataclasses
import time
from collections import defaultdict
from collections.abc import Callable, Sequence
from typing import NamedTuple

import numpy as np

from simrig.plant import Plant
from tsmd.compensation.level_grid import EDGE_LEVEL_SHARE_RANGE
from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.config import TsmdConfig
from tsmd.datasheet_level_grid import TrackedSweep, side_misses, tracked_sweeps
from tsmd.datasheet_unit_run import calibrate_sheet_unit
from tsmd.profile import DeviceModel

MIN_EDGE_LEVEL_GAIN_DEG = 0.5
"""The share is kept where it lowers the sheet unit's side misses' RMS by this much (a quarter
of the 2 deg accuracy target, as the loaded-shape choice's; snakedent's unit 0: 3.25 -> 0.31
deg on phi1, 3.83 -> 0.49 on phi2)."""


class ShareFit(NamedTuple):
    """One knob's share and its side misses' RMS (tip deg) without and with it."""

    share: float
    rms_before_deg: float
    rms_after_deg: float

    @property
    def keep(self) -> bool:
        lo, hi = EDGE_LEVEL_SHARE_RANGE
        return bool(lo <= self.share <= hi
                    and self.rms_before_deg - self.rms_after_deg >= MIN_EDGE_LEVEL_GAIN_DEG)


def fit_share(misses_deg: Sequence[float], moves_deg: Sequence[float]) -> ShareFit:
    """The least-squares share through 0 of the misses over the edge moves (tip deg, one value
    per side and angle); share 0 where the edges never move."""
    m = np.asarray(misses_deg, dtype=float)
    d = np.asarray(moves_deg, dtype=float)
    ok = np.isfinite(m) & np.isfinite(d)
    m, d = m[ok], d[ok]
    if m.size == 0:
        return ShareFit(0.0, float("nan"), float("nan"))
    denom = float(d @ d)
    share = float(d @ m / denom) if denom > 0.0 else 0.0
    before = float(np.sqrt(np.mean(m * m)))
    after = float(np.sqrt(np.mean((m - share * d) ** 2)))
    return ShareFit(share, before, after)


def edge_share(sweeps: Sequence[tuple[float, TrackedSweep]], tension: TensionPlayParams
               ) -> ShareFit | None:
    """One knob's share from the sheet unit's tracked sweeps ``(other knob's grid angle,
    sweep)`` and its calibrated parameters; None without a sweep at the other knob's 0."""
    plain = dataclasses.replace(tension, level_grid=None)
    by_angle: dict[float, list[tuple[float, float]]] = defaultdict(list)
    for other, sweep in sweeps:
        by_angle[float(other)].append(side_misses(sweep, plain))
    if 0.0 not in by_angle:
        return None
    mean = {a: np.nanmean(np.asarray(v), axis=0) for a, v in by_angle.items()}
    grid = np.asarray(plain.other_knob_deg, dtype=float)
    misses, moves = [], []
    for side, edges in enumerate((plain.dead_zone_pos_deg, plain.dead_zone_neg_deg)):
        d = np.asarray(edges, dtype=float)
        zero = float(np.interp(0.0, grid, d))
        for a, m in mean.items():
            misses.append(float(m[side] - mean[0.0][side]))
            moves.append(plain.omega * (float(np.interp(a, grid, d)) - zero))
    return fit_share(misses, moves)


def with_edge_level_share(device: DeviceModel, config: TsmdConfig,
                          factory: Callable[[], Plant], seed: int) -> DeviceModel:
    """``device`` with each knob's ``edge_level_share`` where the sheet's unit, calibrated
    once more and tracked, shows it (:func:`edge_share`); one line per knob."""
    t0 = time.monotonic()
    result = calibrate_sheet_unit(factory, device, "edge-level share", seed, config)
    knobs = list(device.knobs)
    lines = []
    for i, (name, knob) in enumerate(zip(("phi1", "phi2"), device.knobs, strict=True)):
        tension = result.profile.knobs[i].tension_play
        fit = (None if tension is None
               else edge_share(tracked_sweeps(result, i, "edge-level share"), tension))
        if fit is None:
            lines.append(f"{name} no sweep at the other knob's 0")
            continue
        if fit.keep:
            knobs[i] = dataclasses.replace(knob, edge_level_share=round(fit.share, 3))
        lines.append(f"{name} share {fit.share:.3f}, misses' RMS {fit.rms_before_deg:.2f} -> "
                     f"{fit.rms_after_deg:.2f} deg: {'kept' if fit.keep else 'none'}")
    print("  edge-level share on the sheet's unit: " + "; ".join(lines)
          + f" ({time.monotonic() - t0:.0f} s)")
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))
