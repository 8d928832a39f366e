"""How a sheath bend moves a tendon's release line and backlash gain with its dead-zone edge.

The current under compensated motion shows a tendon's dead-zone edge, not its release line
(the release is crossed at the velocity limit; docs/online.md, Session 10). A bend lengthens
the tendon's path and raises its friction; how far the release line at the plateau,
``x_H = D - beta (D - x0)``, moves for each degree the edge ``D`` moves, and how much beta
grows per degree of the release line's move, is a property of the catheter's construction:
measured once by the manufacturer on the data sheet's unit (calibrated straight and bent, a
different unit from those it is used on) and applied by the online estimator when it moves
an edge and the loaded ramps say the friction rose (a bend, not a slack change).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from statistics import median
from typing import Any

from tsmd.online.apply import Offsets, OnlineError
from tsmd.profile import DeviceModel
from tsmd.profile.types import BEND_GAIN_PER_RELEASE_RANGE, BEND_RELEASE_PER_EDGE_RANGE

MIN_EDGE_MOVE_DEG = 0.5
"""A bend that moved an edge less than this says nothing about the relation (calibration
uncertainty, docs/calibration.md)."""

_SIDES = ((1, "dead_zone_pos_deg", "zero_load_pos_deg", "backlash_gain_pos"),
          (-1, "dead_zone_neg_deg", "zero_load_neg_deg", "backlash_gain_neg"))


@dataclass(frozen=True)
class BendRelation:
    """A product's bend relation: release-line move per degree of edge move, and the backlash
    gain's relative growth per degree of release-line move."""

    release_per_edge: float
    gain_per_release_deg: float

    def __post_init__(self) -> None:
        lo, hi = BEND_RELEASE_PER_EDGE_RANGE
        g_lo, g_hi = BEND_GAIN_PER_RELEASE_RANGE
        if not (lo <= self.release_per_edge <= hi and math.isfinite(self.gain_per_release_deg)
                and g_lo <= self.gain_per_release_deg <= g_hi):
            raise OnlineError(f"implausible bend relation: release {self.release_per_edge} "
                              f"per edge deg, gain {self.gain_per_release_deg} per deg")


def sheet_bend_relation(device: DeviceModel | None) -> BendRelation | None:
    """The data sheet's bend relation (None: the sheet has none, and a bend moves x0 with the
    edge as a slack change does)."""
    if device is None or device.bend_release_per_edge is None:
        return None
    assert device.bend_gain_per_release_deg is not None  # the schema reads both or neither
    return BendRelation(device.bend_release_per_edge, device.bend_gain_per_release_deg)


def with_bend_relation(device: DeviceModel, bend: BendRelation) -> DeviceModel:
    """``device`` carrying ``bend`` (rounded as a data sheet is written)."""
    return dataclasses.replace(device, bend_release_per_edge=round(bend.release_per_edge, 3),
                               bend_gain_per_release_deg=round(bend.gain_per_release_deg, 4))


def release_line_deg(edge_deg: float, zero_load_deg: float, gain: float) -> float:
    """Where the release line meets the plateau, outward (``x_H = D - beta (D - x0)``)."""
    return edge_deg - gain * (edge_deg - zero_load_deg)


def tendon_values(profile: Any, knob: int) -> list[tuple[float, float, float]]:
    """(edge, x0, beta) outward per tendon (pos, neg) of ``profile``'s knob, other knob at 0
    (the calibration's own grid point)."""
    tp = profile.knobs[knob].tension_play
    i = min(range(len(tp.other_knob_deg)), key=lambda j: abs(tp.other_knob_deg[j]))
    return [(s * getattr(tp, d)[i], s * getattr(tp, x)[i], float(getattr(tp, b)[i]))
            for s, d, x, b in _SIDES]


def measure_bend_relation(straight: Any, bent: Sequence[Any]) -> BendRelation:
    """The relation from one unit's calibrations, straight and after one or more bends: the
    medians over every tendon and bend of ``dx_H / dD`` and ``(beta ratio - 1) / dx_H``."""
    per_edge: list[float] = []
    gain: list[float] = []
    for profile in bent:
        for knob in (0, 1):
            for (d0, x0, b0), (d1, x1, b1) in zip(tendon_values(straight, knob),
                                                  tendon_values(profile, knob), strict=True):
                move = d1 - d0
                release = release_line_deg(d1, x1, b1) - release_line_deg(d0, x0, b0)
                if abs(move) < MIN_EDGE_MOVE_DEG or abs(release) < MIN_EDGE_MOVE_DEG or b0 <= 0:
                    continue
                per_edge.append(release / move)
                gain.append((b1 / b0 - 1.0) / release)
    if not per_edge:
        raise OnlineError("no bend moved an edge by 0.5 deg or more: no bend relation")
    return BendRelation(float(median(per_edge)), float(median(gain)))


def zero_load_move_deg(edge_deg: float, zero_load_deg: float, gain: float, edge_move_deg: float,
                       release_move_deg: float, gain_ratio: float) -> float:
    """How far x0 must move outward so that, with the edge moved by ``edge_move_deg`` and beta
    scaled by ``gain_ratio``, the release line moves by ``release_move_deg`` (a slack change:
    both moves equal and the gain kept, x0 moves with the edge)."""
    new_gain = gain * gain_ratio
    if new_gain <= 1e-3:
        return edge_move_deg
    x_h = release_line_deg(edge_deg, zero_load_deg, gain) + release_move_deg
    new_edge = edge_deg + edge_move_deg
    return new_edge - (new_edge - x_h) / new_gain - zero_load_deg


def bend_targets(bend: BendRelation, trackers: Mapping[tuple[int, int], Any],
                 knobs: Sequence[Any]) -> tuple[Offsets, Offsets]:
    """(x0 moves, backlash gain ratios) per edge, in the offsets' layout: the release line
    moves ``e (1 + w (r - 1))`` for an edge move ``e`` with bend share ``w``
    (:attr:`EdgeTracker.bend_weight`), beta by ``1 + w c`` per degree of that (or as the
    loaded slope says, without :attr:`EstimatorOptions.gain_from_bend`); x0 is placed to
    give both (the paper's knobs have neither: x0 moves with the edge)."""
    r, c = bend.release_per_edge, bend.gain_per_release_deg
    zero = [[0.0, 0.0], [0.0, 0.0]]
    gain = [[1.0, 1.0], [1.0, 1.0]]
    for (knob, side), tr in trackers.items():
        j = 0 if side > 0 else 1
        e, w, o = tr.applied_deg, tr.bend_weight, tr.options
        if tr.last_feature == "knee" and not o.bend_in_knee_mode:
            zero[knob][j], gain[knob][j] = tr.zero_load_deg, tr.gain_ratio
            continue
        release = e * (1.0 + w * (r - 1.0))
        g = (min(max(1.0 + w * c * release, 1.0 / o.slope_ratio_max), o.slope_ratio_max)
             if o.gain_from_bend else tr.gain_ratio)
        gain[knob][j] = g
        field = knobs[knob].field
        try:
            cols = [field.column(n) for n in _SIDES[j][1:]]
        except KeyError:  # the paper's knob: no x0, no beta
            zero[knob][j] = e
            continue
        values = field.at(0.0)
        zero[knob][j] = zero_load_move_deg(side * float(values[cols[0]]),
                                           side * float(values[cols[1]]),
                                           float(values[cols[2]]), e, release, g)
    return (((zero[0][0], zero[0][1]), (zero[1][0], zero[1][1])),
            ((gain[0][0], gain[0][1]), (gain[1][0], gain[1][1])))


__all__ = ["BendRelation", "bend_targets", "measure_bend_relation", "release_line_deg",
           "sheet_bend_relation", "tendon_values", "with_bend_relation", "zero_load_move_deg"]
