"""Dead-zone edge offsets applied to a compensator's knobs, and saved as a new profile version.

An offset moves one edge outward (positive: a wider dead zone, e.g. more slack after the shaft
was bent). A slack change moves the tendon's whole characteristic along the knob axis, so the
loaded line and (for our compensator) the zero-load point of that tendon move with its edge,
while the plateau heights H stay: the tip's plateaus do not depend on where the tendon engages.
"""

from __future__ import annotations

import os
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from tsmd.calibration.unit_slope import unit_omega
from tsmd.compensation.ours_table import MOVES_WITH_EDGE, OursKnob
from tsmd.compensation.paper import PaperKnob
from tsmd.compensation.tension_play_params import BETA_RANGE
from tsmd.errors import TsmdError
from tsmd.profile import CatheterProfile, KnobProfile, ReferencePoint, save_profile

Offsets = tuple[tuple[float, float], tuple[float, float]]
"""Per knob (phi1, phi2): (outward offset of D_pos, outward offset of D_neg), degrees."""

ZERO_OFFSETS: Offsets = ((0.0, 0.0), (0.0, 0.0))


ONE_GAINS: Offsets = ((1.0, 1.0), (1.0, 1.0))
"""Backlash gain ratios (pos, neg) per knob that leave the profile's beta."""
GAIN_STEP = 0.05
"""The published backlash gain ratios move in steps of at least this (or to the target)."""


def towards(current: Offsets, target: Offsets, step: float) -> Offsets:
    """Each value moved towards its target by at most ``step``."""
    (a, b), (c, d) = ((x + max(-step, min(step, g - x)) for x, g in zip(cur, tgt, strict=True))
                      for cur, tgt in zip(current, target, strict=True))
    return ((a, b), (c, d))


class OnlineError(TsmdError):
    """Online estimates cannot be applied or saved as asked."""


def bent_omega(omega: float, gain_before: float, gain_after: float,
               omega_per_gain: float | None = None) -> float:
    """The tension play's omega after the knob's mean backlash gain moved: by the
    release-slope relation (:func:`unit_omega`), or with a product's bend relation that says
    otherwise by ``omega_per_gain`` per relative gain change
    (:attr:`tsmd.online.bend.BendRelation.omega_per_gain`)."""
    if omega_per_gain is None or gain_before <= 0:
        return unit_omega(omega, gain_before, gain_after)
    return omega * (1.0 + omega_per_gain * (gain_after / gain_before - 1.0))


def shifted_knob(knob: Any, offset: tuple[float, float],
                 gain_ratio: tuple[float, float] = (1.0, 1.0),
                 zero_load: tuple[float, float] | None = None,
                 omega_per_gain: float | None = None) -> Any:
    """A copy of a compensator knob (ours or the paper's) with its edges moved outward.

    Ours: each tendon's zero-load point moves outward by ``zero_load`` (pos, neg; None: with
    its edge, the whole characteristic moves as after a slack change; a sheath bend moves the
    edge and keeps x0, :attr:`EdgeTracker.zero_load_deg`); ``gain_ratio`` (pos, neg)
    multiplies each tendon's backlash gain beta (a sheath bend: the backlash grows with the
    tension per knob degree, :attr:`EdgeTracker.gain_ratio`), and omega follows the
    calibration's relation (the release slope ``omega / (1 - beta)`` is the product's), or the
    bend relation's ``omega_per_gain`` (:func:`bent_omega`).
    """
    off_pos, off_neg = offset
    moves = {"dead_zone_pos_deg": off_pos, "dead_zone_neg_deg": -off_neg}
    if isinstance(knob, OursKnob):
        x0_pos, x0_neg = offset if zero_load is None else zero_load
        moves.update({MOVES_WITH_EDGE["dead_zone_pos_deg"]: x0_pos,
                      MOVES_WITH_EDGE["dead_zone_neg_deg"]: -x0_neg})
        field = knob.field.shifted(moves)
        if gain_ratio == (1.0, 1.0):
            return replace(knob, field=field)
        field = field.scaled({"backlash_gain_pos": gain_ratio[0],
                              "backlash_gain_neg": gain_ratio[1]}, BETA_RANGE)
        omega = bent_omega(knob.omega, _beta_at_zero(knob.field), _beta_at_zero(field),
                           omega_per_gain)
        return replace(knob, field=field, omega=omega)
    if not isinstance(knob, PaperKnob):
        raise OnlineError(f"online re-estimation cannot shift a {type(knob).__name__}")
    return replace(knob, field=knob.field.shifted(moves))


def _beta_at_zero(field: Any) -> float:
    """The mean backlash gain of both tendons with the other knob at 0 (as the calibration)."""
    values = field.at(0.0)
    return 0.5 * float(values[field.column("backlash_gain_pos")]
                       + values[field.column("backlash_gain_neg")])


def edges_at(knob: Any, other_deg: float) -> tuple[float, float]:
    """(D_pos, D_neg) a compensator knob uses at the other knob's angle."""
    values = knob.field.at(other_deg)
    return (float(values[knob.field.column("dead_zone_pos_deg")]),
            float(values[knob.field.column("dead_zone_neg_deg")]))


def apply_knobs(compensator: Any, knobs: tuple[Any, Any]) -> None:
    """Hand new knobs to the compensator (called on the loop thread, between two ticks)."""
    replace_knobs = getattr(compensator, "replace_knobs", None)
    if replace_knobs is not None:
        replace_knobs(knobs)
    else:
        compensator.knobs = knobs


def profile_with_offsets(profile: CatheterProfile, offsets: Offsets, note: str = "",
                         gains: Offsets = ((1.0, 1.0), (1.0, 1.0)),
                         zero_loads: Offsets | None = None,
                         omega_per_gain: float | None = None) -> CatheterProfile:
    """The profile with its edges moved by ``offsets``, its tension play's zero-load points
    by ``zero_loads`` (None: with the edges) and its backlash gains multiplied by ``gains``
    (same catheter, a new version; omega as :func:`shifted_knob`).

    The reference points move with the edges, so the plateau heights stay what the
    calibration gave (H from the reference point through D(0), design assumption 1).
    """
    knobs = []
    lo, hi = BETA_RANGE
    for k, (off_pos, off_neg), (g_pos, g_neg), (x0_pos, x0_neg) in zip(
            profile.knobs, offsets, gains, offsets if zero_loads is None else zero_loads,
            strict=True):
        ours = k.tension_play
        if ours is not None:
            beta_pos = tuple(min(max(v * g_pos, lo), hi) for v in ours.backlash_gain_pos)
            beta_neg = tuple(min(max(v * g_neg, lo), hi) for v in ours.backlash_gain_neg)
            grid = ours.other_knob_deg

            def at_zero(pos: tuple[float, ...], neg: tuple[float, ...],
                        grid: tuple[float, ...] = grid) -> float:
                return 0.5 * float(np.interp(0.0, grid, pos) + np.interp(0.0, grid, neg))

            ours = replace(
                ours, dead_zone_pos_deg=tuple(v + off_pos for v in ours.dead_zone_pos_deg),
                dead_zone_neg_deg=tuple(v - off_neg for v in ours.dead_zone_neg_deg),
                zero_load_pos_deg=tuple(v + x0_pos for v in ours.zero_load_pos_deg),
                zero_load_neg_deg=tuple(v - x0_neg for v in ours.zero_load_neg_deg),
                backlash_gain_pos=beta_pos, backlash_gain_neg=beta_neg,
                omega=bent_omega(ours.omega, at_zero(ours.backlash_gain_pos,
                                                     ours.backlash_gain_neg),
                                 at_zero(beta_pos, beta_neg), omega_per_gain))
        moved = KnobProfile(
            k.omega, ReferencePoint(k.reference_pos.knob_deg + off_pos, k.reference_pos.tip_deg),
            ReferencePoint(k.reference_neg.knob_deg - off_neg, k.reference_neg.tip_deg),
            k.height_pos_deg, k.height_neg_deg, k.other_knob_deg,
            tuple(float(v) + off_pos for v in k.dead_zone_pos_deg),
            tuple(float(v) - off_neg for v in k.dead_zone_neg_deg),
            k.backlash_pos_deg, k.backlash_neg_deg, ours)
        if k.paper is not None:  # the paper's frame (session 27) moves with the edges
            moved = replace(moved, paper=replace(
                k.paper, reference_pos=moved.reference_pos, reference_neg=moved.reference_neg,
                dead_zone_pos_deg=tuple(float(v) + off_pos for v in k.paper.dead_zone_pos_deg),
                dead_zone_neg_deg=tuple(float(v) - off_neg for v in k.paper.dead_zone_neg_deg)))
        knobs.append(moved)
    quality = dict(profile.quality)
    for i, ((off_pos, off_neg), (g_pos, g_neg), (x0_pos, x0_neg)) in enumerate(zip(
            offsets, gains, offsets if zero_loads is None else zero_loads, strict=True)):
        quality[f"phi{i + 1}_online_offset_pos_deg"] = float(off_pos)
        quality[f"phi{i + 1}_online_offset_neg_deg"] = float(off_neg)
        quality[f"phi{i + 1}_online_zero_load_offset_pos_deg"] = float(x0_pos)
        quality[f"phi{i + 1}_online_zero_load_offset_neg_deg"] = float(x0_neg)
        quality[f"phi{i + 1}_online_backlash_gain_ratio_pos"] = float(g_pos)
        quality[f"phi{i + 1}_online_backlash_gain_ratio_neg"] = float(g_neg)
    now = datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
    source = (f"online re-estimation from motor current, {now}, on the calibration of "
              f"{profile.calibrated_at} ({profile.source})" + (f"; {note}" if note else ""))
    return replace(profile, knobs=(knobs[0], knobs[1]), source=source, quality=quality,
                   calibrated_at=now)


def save_online_version(profile: CatheterProfile, offsets: Offsets,
                        directory: str | os.PathLike[str], note: str = "",
                        gains: Offsets = ((1.0, 1.0), (1.0, 1.0)),
                        zero_loads: Offsets | None = None,
                        omega_per_gain: float | None = None) -> Path:
    """Save the online estimates as ``<dir>/<catheter_id>.online-<UTC time>.yaml``.

    Never overwrites: not the calibrated ``<catheter_id>.yaml``, not an earlier version.
    """
    if not all(np.isfinite(v) for pair in (*offsets, *(zero_loads or ())) for v in pair):
        raise OnlineError(f"online offsets must be finite, got {offsets}, {zero_loads}")
    if not all(np.isfinite(v) and v > 0 for pair in gains for v in pair):
        raise OnlineError(f"online backlash gain ratios must be finite and > 0, got {gains}")
    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%S")
    path = Path(directory) / f"{profile.catheter_id}.online-{stamp}.yaml"
    n = 1
    while path.exists():
        n += 1
        path = Path(directory) / f"{profile.catheter_id}.online-{stamp}-{n}.yaml"
    save_profile(profile_with_offsets(profile, offsets, note, gains, zero_loads,
                                      omega_per_gain), path)
    return path
