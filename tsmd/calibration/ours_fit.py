"""Our compensator's extra parameters (:class:`tsmd.compensation.ours.OursParams`) fitted on the
calibration sweeps: current-only data plus the data sheet's constants.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.lag import estimate_lag_s
from tsmd.compensation.ours import OursParams, release_line, release_line_from_reference
from tsmd.compensation.paper import at_other_knob_zero, offset_edges, plateau_heights
from tsmd.profile import DeviceModel


@dataclass(frozen=True)
class SweepData:
    """One calibration sweep of one knob with the other knob held at ``other_knob_deg``.

    Arrays of equal length, uncompensated: ``cmd_deg`` commanded and ``pos_deg`` actual knob
    angle, ``current_A`` the knob motor's current (filtered or raw: it is filtered again here).
    ``dead_zone_*``/``backlash_*`` are what the paper's identification found for this sweep.
    """

    t_s: NDArray[np.float64]
    cmd_deg: NDArray[np.float64]
    pos_deg: NDArray[np.float64]
    current_A: NDArray[np.float64]
    other_knob_deg: float
    dead_zone_pos_deg: float
    dead_zone_neg_deg: float
    backlash_pos_deg: float
    backlash_neg_deg: float


def heights_from_sweeps(sweeps: Sequence[SweepData], device_knob: Any,
                        dead_zone_offset_deg: float = 0.0) -> tuple[float, float]:
    """H_pos, H_neg by design assumptions 1-3: the data sheet's reference points and slope with
    the dead-zone edges identified with the other knob at 0 deg (interpolated over the sweeps),
    moved outward by ``dead_zone_offset_deg``."""
    order = sorted(sweeps, key=lambda s: s.other_knob_deg)
    grid = [s.other_knob_deg for s in order]
    d_pos0, d_neg0 = offset_edges(
        at_other_knob_zero(grid, [s.dead_zone_pos_deg for s in order]),
        at_other_knob_zero(grid, [s.dead_zone_neg_deg for s in order]), dead_zone_offset_deg)
    return plateau_heights(device_knob, float(d_pos0), float(d_neg0))


def fit_ours_knob(sweeps: Sequence[SweepData], device_knob: Any,
                  other_knob_deg: Sequence[float] | None = None) -> OursParams:
    """Our extra parameters for one knob from its calibration sweeps (current-only data).

    ``sweeps``: every sweep of this knob, each tagged with the other knob's angle and the D/B the
    paper's identification found in its current. ``device_knob``: the data sheet's
    :class:`tsmd.profile.DeviceKnob` (omega, reference points) that also gives the profile's H.
    ``other_knob_deg``: the profile's grid (default: the sweeps' other-knob angles, sorted); each
    grid point needs a sweep within 1 deg (several are combined by the median).

    Release lines: the data sheet's release slope and reference backlash, moved with each
    sweep's D (:func:`release_line_from_reference`), or, without them, from the sweep's
    amplitude (actual knob position), D and B (:func:`release_line`). Lag: commanded vs actual
    position, median over the sweeps. The backlash blend is 0 (corners): its identification is
    not built yet.
    """
    if not sweeps:
        raise ValueError("fit_ours_knob needs at least one sweep")
    for s in sweeps:
        values = (s.dead_zone_pos_deg, s.dead_zone_neg_deg, s.backlash_pos_deg,
                  s.backlash_neg_deg)
        if not all(math.isfinite(v) for v in values):
            raise ValueError(f"sweep at {s.other_knob_deg} deg has no finite D/B: {values}")
    omega = float(device_knob.omega)
    release_omega = getattr(device_knob, "release_omega", None)
    ref_b_pos = getattr(device_knob, "reference_backlash_pos_deg", None)
    ref_b_neg = getattr(device_knob, "reference_backlash_neg_deg", None)
    dz_offset = float(getattr(device_knob, "dead_zone_offset_deg", None) or 0.0)
    h_pos, h_neg = heights_from_sweeps(sweeps, device_knob, dz_offset)
    grid = sorted({float(s.other_knob_deg) for s in sweeps}) if other_knob_deg is None else list(
        other_knob_deg)
    order = sorted(sweeps, key=lambda s: s.other_knob_deg)
    at_zero = [float(np.interp(0.0, [s.other_knob_deg for s in order],
                               [getattr(s, name) for s in order]))
               for name in ("dead_zone_pos_deg", "dead_zone_neg_deg")]
    columns: list[list[float]] = [[], [], [], []]
    for g in grid:
        near = [s for s in sweeps if abs(s.other_knob_deg - g) <= 1.0]
        if not near:
            raise ValueError(f"no sweep with the other knob at {g} deg")
        lines: list[tuple[float, float, float, float]] = []
        for s in near:
            pos = np.asarray(s.pos_deg, float)
            pos = pos[np.isfinite(pos)]
            if pos.size == 0:
                raise ValueError(f"sweep at {g} deg has no finite position")
            if release_omega is not None and ref_b_pos is not None and ref_b_neg is not None:
                k = device_knob
                sp, pp = release_line_from_reference(
                    k.reference_pos.knob_deg - ref_b_pos, k.reference_pos.tip_deg, h_neg,
                    release_omega, s.dead_zone_pos_deg - at_zero[0])
                sn, pn = release_line_from_reference(
                    k.reference_neg.knob_deg + ref_b_neg, k.reference_neg.tip_deg, h_pos,
                    release_omega, s.dead_zone_neg_deg - at_zero[1])
            else:
                edge_pos, edge_neg = offset_edges(s.dead_zone_pos_deg, s.dead_zone_neg_deg,
                                                  dz_offset)
                sp, pp = release_line(float(pos.max()), float(edge_pos), s.backlash_pos_deg,
                                      h_pos, h_neg, omega)
                sn, pn = release_line(float(pos.min()), float(edge_neg), s.backlash_neg_deg,
                                      h_neg, h_pos, omega)
            lines.append((sp, sn, pp, pn))
        for j in range(4):
            columns[j].append(float(np.median([line[j] for line in lines])))
    lag = float(np.median([estimate_lag_s(s.t_s, s.cmd_deg, s.pos_deg) for s in sweeps]))
    n = len(grid)
    return OursParams(min(lag, 1.0), tuple(columns[0]), tuple(columns[1]), tuple(columns[2]),
                      tuple(columns[3]), (0.0,) * n, dz_offset)


def fit_ours_for_knob(points: Sequence[GridPoint], device: DeviceModel, knob: int
                      ) -> OursParams:
    """``fit_ours_knob`` on the current-only data of the sweeps."""
    sweeps = []
    for p in sorted(points, key=lambda q: q.other_deg):
        d = p.result.data
        sweeps.append(SweepData(
            t_s=d.t_s, cmd_deg=d.cmd_deg, pos_deg=d.pos_deg, current_A=d.current_A,
            other_knob_deg=float(p.other_deg),
            dead_zone_pos_deg=p.result.estimate("dead_zone_pos_deg"),
            dead_zone_neg_deg=p.result.estimate("dead_zone_neg_deg"),
            backlash_pos_deg=p.result.estimate("backlash_pos_deg"),
            backlash_neg_deg=p.result.estimate("backlash_neg_deg")))
    return fit_ours_knob(sweeps, device.knobs[knob])
