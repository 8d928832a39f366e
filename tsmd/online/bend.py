"""How a sheath bend moves a tendon's release line and backlash gain with its dead-zone edge.

The current under compensated motion shows a tendon's dead-zone edge, not its release line
(the release is crossed at the velocity limit; docs/online.md, Session 10). A bend lengthens
the tendon's path and raises its friction; how far the release line at the plateau,
``x_H = D - beta (D - x0)``, moves for each degree the edge ``D`` moves, and how much beta
grows per degree of the release line's move, is a property of the catheter's construction:
measured once by the manufacturer on the data sheet's unit (calibrated straight and bent, a
different unit from those it is used on) and applied by the online estimator when it moves
an edge and the loaded ramps say the friction rose (a bend, not a slack change).

Some products' bends move no edge at all and still grow the backlash (the rate-and-state plant:
unit 0 at 60 deg, edges -0.38..-0.12 deg, beta 1.19-1.25 x with x0 where it was, omega -4.4 %,
while the loaded ramps run ~1.2-1.3 x steeper, session 22). For them the relation carries beta's
relative growth per unit of the loaded ramps' slope rise (what the current shows) and omega's
relative change per relative change of beta.
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
from tsmd.profile.device import (
    BEND_GAIN_PER_RELEASE_RANGE,
    BEND_GAIN_PER_SLOPE_RANGE,
    BEND_OMEGA_PER_GAIN_RANGE,
    BEND_RELEASE_PER_EDGE_RANGE,
)

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
    gain_per_slope: float = 0.0
    """Beta's relative growth per unit of the knob's loaded-slope rise in a bend that moves no
    edge of the knob, x0 kept; 0: such a bend moves nothing."""
    omega_per_gain: float | None = None
    """The tension play's omega's relative change per relative change of the knob's mean
    beta in a bend; None: omega follows the release-slope relation (:func:`unit_omega`)."""

    def __post_init__(self) -> None:
        lo, hi = BEND_RELEASE_PER_EDGE_RANGE
        g_lo, g_hi = BEND_GAIN_PER_RELEASE_RANGE
        s_lo, s_hi = BEND_GAIN_PER_SLOPE_RANGE
        o_lo, o_hi = BEND_OMEGA_PER_GAIN_RANGE
        if not (lo <= self.release_per_edge <= hi and math.isfinite(self.gain_per_release_deg)
                and g_lo <= self.gain_per_release_deg <= g_hi):
            raise OnlineError(f"implausible bend relation: release {self.release_per_edge} "
                              f"per edge deg, gain {self.gain_per_release_deg} per deg")
        if not (s_lo <= self.gain_per_slope <= s_hi and (
                self.omega_per_gain is None or o_lo <= self.omega_per_gain <= o_hi)):
            raise OnlineError(f"implausible bend relation: gain {self.gain_per_slope} per slope "
                              f"rise, omega {self.omega_per_gain} per gain")


def sheet_bend_relation(device: DeviceModel | None) -> BendRelation | None:
    """The data sheet's bend relation (None: the sheet has none, and a bend moves x0 with the
    edge as a slack change does)."""
    if device is None or device.bend_release_per_edge is None:
        return None
    assert device.bend_gain_per_release_deg is not None  # the schema reads both or neither
    return BendRelation(device.bend_release_per_edge, device.bend_gain_per_release_deg,
                        device.bend_gain_per_slope or 0.0, device.bend_omega_per_gain)


def with_bend_relation(device: DeviceModel, bend: BendRelation) -> DeviceModel:
    """``device`` carrying ``bend`` (rounded as a data sheet is written; the slope terms only
    when measured)."""
    return dataclasses.replace(
        device, bend_release_per_edge=round(bend.release_per_edge, 3),
        bend_gain_per_release_deg=round(bend.gain_per_release_deg, 4),
        bend_gain_per_slope=round(bend.gain_per_slope, 3) if bend.gain_per_slope else None,
        bend_omega_per_gain=(None if bend.omega_per_gain is None
                             else round(bend.omega_per_gain, 3)))


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


def measure_bend_relation(straight: Any, bent: Sequence[Any],
                          slope_rises: Sequence[tuple[float, float]] | None = None
                          ) -> BendRelation:
    """The relation from one unit's calibrations, straight and after one or more bends: the
    medians over every tendon and bend of ``dx_H / dD`` and ``(beta ratio - 1) / dx_H``.

    With ``slope_rises`` (per bend, each knob's loaded-slope rise the online estimator read,
    :func:`tsmd.datasheet_bend_slope.rig_slope_reader`): over the knobs whose bend moved no
    edge by :data:`MIN_EDGE_MOVE_DEG`, the median of ``(beta ratio - 1) / rise`` per tendon;
    and over every knob and bend that moved its mean beta by 1 % or more, the median of
    ``(omega ratio - 1) / (mean beta ratio - 1)``. The edge relation defaults to the slack's
    (1, 0) when no bend moved an edge."""
    per_edge: list[float] = []
    gain: list[float] = []
    per_slope: list[float] = []
    omega: list[float] = []
    for i, profile in enumerate(bent):
        for knob in (0, 1):
            pairs = list(zip(tendon_values(straight, knob), tendon_values(profile, knob),
                             strict=True))
            for (d0, x0, b0), (d1, x1, b1) in pairs:
                move = d1 - d0
                release = release_line_deg(d1, x1, b1) - release_line_deg(d0, x0, b0)
                if abs(move) < MIN_EDGE_MOVE_DEG or abs(release) < MIN_EDGE_MOVE_DEG or b0 <= 0:
                    continue
                per_edge.append(release / move)
                gain.append((b1 / b0 - 1.0) / release)
            if slope_rises is None:
                continue
            rise = slope_rises[i][knob]
            if rise > 0.0 and all(abs(b[0] - a[0]) < MIN_EDGE_MOVE_DEG for a, b in pairs):
                per_slope += [(b[2] / a[2] - 1.0) / rise for a, b in pairs if a[2] > 0]
            omega += _omega_per_gain(straight, profile, knob)
    if not per_edge and not per_slope:
        raise OnlineError("no bend moved an edge by 0.5 deg or more: no bend relation")
    return BendRelation(float(median(per_edge)) if per_edge else 1.0,
                        float(median(gain)) if gain else 0.0,
                        float(median(per_slope)) if per_slope else 0.0,
                        float(median(omega)) if omega and per_slope else None)


def _omega_per_gain(straight: Any, bent: Any, knob: int) -> list[float]:
    """The bent calibration's omega ratio minus 1 over its mean beta ratio minus 1 (none when
    beta moved less than 1 %: nothing to divide)."""
    b0 = 0.5 * sum(v[2] for v in tendon_values(straight, knob))
    b1 = 0.5 * sum(v[2] for v in tendon_values(bent, knob))
    if b0 <= 0 or abs(b1 / b0 - 1.0) < 0.01:
        return []
    w0, w1 = straight.knobs[knob].tension_play.omega, bent.knobs[knob].tension_play.omega
    return [(w1 / w0 - 1.0) / (b1 / b0 - 1.0)]


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


def slope_rise(tracker: Any) -> float:
    """The knob's loaded-slope rise a bend shows: the pooled change of both tendons' last
    ramps (:attr:`EdgeTracker.knob_change`) while both got steeper beyond the same-slope
    tolerance (:attr:`EdgeTracker.knee_direction`) or the pooled change itself is beyond it
    (one tendon's median at the tolerance's edge made the rise flicker off on ratestate
    development 2, session 22), else 0 (without a change each tendon's median stays within
    0.09 over 600 s on ratestate and coilpipe 1, session 21's no-change runs)."""
    change = float(tracker.knob_change)
    steeper = tracker.knee_direction > 0 or change > tracker.options.same_slope_tolerance
    return max(change, 0.0) if steeper else 0.0


def bend_targets(bend: BendRelation, trackers: Mapping[tuple[int, int], Any],
                 knobs: Sequence[Any]) -> tuple[Offsets, Offsets]:
    """(x0 moves, backlash gain ratios) per edge, in the offsets' layout: the release line
    moves ``e (1 + w (r - 1))`` for an edge move ``e`` with bend share ``w``
    (:attr:`EdgeTracker.bend_weight`), beta by ``1 + w c`` per degree of that (or as the
    loaded slope says, without :attr:`EstimatorOptions.gain_from_bend`); x0 is placed to
    give both (the paper's knobs have neither: x0 moves with the edge). Where no edge of the
    knob followed a change and the relation has a gain per slope rise, beta grows by that
    times the knob's slope rise (:func:`slope_rise`) and x0 stays."""
    r, c = bend.release_per_edge, bend.gain_per_release_deg
    zero = [[0.0, 0.0], [0.0, 0.0]]
    gain = [[1.0, 1.0], [1.0, 1.0]]
    for (knob, side), tr in trackers.items():
        j = 0 if side > 0 else 1
        e, w, o = tr.applied_deg, tr.bend_weight, tr.options
        if bend.gain_per_slope and not tr.knob_followed:  # a bend that moves no edge
            rise = slope_rise(tr)
            gain[knob][j] = min(max(1.0 + bend.gain_per_slope * rise, 1.0 / o.slope_ratio_max),
                                o.slope_ratio_max)
            continue  # x0 kept (zero[knob][j] = 0)
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


__all__ = ["BendRelation", "bend_targets", "measure_bend_relation",
           "release_line_deg", "sheet_bend_relation", "slope_rise", "tendon_values",
           "with_bend_relation", "zero_load_move_deg"]
