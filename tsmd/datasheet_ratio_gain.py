"""The gain the product's release ratio is taken against, chosen by tracking on the sheet's unit
(session 22).

Method ours moves each unit's release line by the sheet's ratio ``release_omega (1 - gain) /
omega`` (:mod:`tsmd.compensation.release_ratio`), the gain the settle rule's or the product rule's
reading of the sheet unit's backlash. Which one tracks better is the product's: on cyclopebax phi2
the rule's (unit 0's 1-DOF RMSE reduction 74 -> 85 %), on nitinol the settle rule's (93 -> 88 %
with the rule's; docs/calibration.md "Session 21"). The slope alone does not tell them apart
(the gain also scales the backlash to smaller reversals), so the sheet's unit is calibrated
under each gain, its tip tracked through the paper's quick 1-DOF rows of each knob with method
ours, and the gain with the lower mean RMSE per knob is written as ``release_ratio_gain`` where
it differs from what the sheet chooses without the field by more than :data:`MIN_RMSE_GAIN`.

A knob whose tracked release the sheet left out (its ratio against the default gain outside the
range) is offered it back against the other gain where that ratio is in range (cyclopebax phi1:
0.69 against the settle gain, 0.94 against the rule's). With ``offer_none`` (opt-in per product,
``--ratio-gain-none``) a knob is also offered no tracked release at all (ratio 1): cyclopebax
phi2 takes it on unit 0 (2.02 deg against 3.38 with the rule's gain); nitinol and segments do not
(docs/model.md "Session 22").
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence

import numpy as np

from simrig.plant import Plant
from tsmd.compensation.release_ratio import ratio_gain, release_ratio_problem
from tsmd.config import TsmdConfig
from tsmd.datasheet_unit_run import SHEET_UNIT_SEED, calibrate_sheet_unit
from tsmd.profile import CatheterProfile, DeviceKnob, DeviceModel
from tsmd.replay import run_trajectory
from tsmd.tracking_scenarios import Scenario, conditioned, scenarios, tracking_errors

GAINS: tuple[str, str] = ("settle", "rule")
"""The two readings of the sheet unit's backlash gain the ratio can be taken against."""
TRACK_SEED = 0
"""Noise seed of the tracking runs (the accuracy bench's); the calibration takes the sheet's."""
NO_RELEASE = "none"
"""The option of no tracked release on the knob (ratio 1: each unit's release line is the locus
its own current's beta and x0 give); offered only with ``offer_none`` (``--ratio-gain-none``)."""
SHEET = "sheet"
"""The option of a knob as the sheet stands (its default gain, or no tracked release)."""
MIN_RMSE_GAIN = 0.05
"""The other gain must track with a mean RMSE this fraction lower than the sheet's default to be
written: above the noise of one run (cyclopebax unit 0's phi1 tracked 1.88 and 1.93 deg in two
runs that differed only in phi2's sheet); the choices made on unit 0 in session 22 differ by
16-70 %."""


def default_gain(knob: DeviceKnob) -> str | None:
    """The gain the sheet takes without ``release_ratio_gain`` ("settle" or "rule"), None where
    the knob has no ratio to take (no ``release_omega`` or no rule gain)."""
    if knob.release_omega is None or knob.reference_rule_backlash_gain is None:
        return None
    gain = ratio_gain(dataclasses.replace(knob, release_ratio_gain=None))
    return "settle" if gain == knob.reference_backlash_gain else "rule"


def candidate(knob: DeviceKnob, gain: str, dropped_release_omega: float | None
              ) -> DeviceKnob | None:
    """The knob with its ratio taken against ``gain`` (its left-out tracked release restored
    where that makes the ratio usable), or without its tracked release for
    :data:`NO_RELEASE`; None where the knob cannot take ``gain``."""
    if gain == NO_RELEASE:
        return (None if knob.release_omega is None
                else dataclasses.replace(knob, release_omega=None, release_ratio_gain=None))
    if knob.reference_rule_backlash_gain is None or knob.reference_backlash_gain is None:
        return None
    release = knob.release_omega if knob.release_omega is not None else dropped_release_omega
    if release is None:
        return None
    out = dataclasses.replace(knob, release_omega=release, release_ratio_gain=gain)
    return None if release_ratio_problem(out) is not None else out


def alternatives(knob: DeviceKnob, dropped_release_omega: float | None,
                 offer_none: bool = False) -> list[str]:
    """The gains the knob could take other than the one it takes as the sheet stands (and,
    with ``offer_none``, no tracked release)."""
    default = default_gain(knob)
    options = (*GAINS, NO_RELEASE) if offer_none else GAINS
    return [g for g in options
            if g != default and candidate(knob, g, dropped_release_omega) is not None]


def choose(score: dict[str, float]) -> str | None:
    """The ``release_ratio_gain`` to write from one knob's mean RMSE per option ("sheet": as
    the sheet stands, else a gain): the best gain where it beats the sheet by
    :data:`MIN_RMSE_GAIN`, else None."""
    base = score.get(SHEET)
    others = [(g, s) for g, s in score.items() if g != SHEET and math.isfinite(s)]
    if base is None or not others:
        return None
    best, best_deg = min(others, key=lambda x: x[1])
    return best if best_deg < (1.0 - MIN_RMSE_GAIN) * base else None


def knob_rows(knob: int, quick: Sequence[Scenario]) -> list[Scenario]:
    """The paper's quick 1-DOF rows that move ``knob``."""
    return [s for s in quick if s.group.startswith("1-DOF") and s.knobs == (knob,)]


def track_rmse_deg(s: Scenario, profile: CatheterProfile, factory: Callable[[], Plant],
                   config: TsmdConfig | None, seed: int = TRACK_SEED) -> float:
    """Method ours' tracking RMSE (deg) of the scenario's knob on the sheet's unit, after one
    conditioning cycle (as the accuracy bench runs it)."""
    tt, qq, skip = conditioned(s.t_s, s.q_deg, True)
    rec = run_trajectory(tt, qq, config=config, profile=profile, method="ours", seed=seed,
                         plant=factory())
    k = s.knobs[0]
    return tracking_errors(np.asarray(rec[f"tip{k + 1}"])[skip:], qq[skip:, k])[1]


def track_gain(factory: Callable[[], Plant], device: DeviceModel, config: TsmdConfig | None,
               seed: int, knobs: Sequence[int]) -> dict[int, float]:
    """Mean tracking RMSE (deg) of method ours per knob in ``knobs`` on the sheet's unit,
    calibrated under ``device`` by the paper protocol."""
    profile = calibrate_sheet_unit(factory, device, "ratio gain", seed, config).profile
    quick = scenarios(quick=True)
    return {k: float(np.mean([track_rmse_deg(s, profile, factory, config)
                              for s in knob_rows(k, quick)])) for k in knobs}


def measure_gain_scores(factory: Callable[[], Plant], device: DeviceModel,
                        dropped_release_omega: Sequence[float | None] = (None, None),
                        config: TsmdConfig | None = None, seed: int = SHEET_UNIT_SEED,
                        track: Callable[..., dict[int, float]] = track_gain,
                        offer_none: bool = False) -> tuple[dict[str, float], dict[str, float]]:
    """Each knob's mean RMSE per option: the sheet as it stands (without a
    ``release_ratio_gain``), then each other usable gain
    (one calibration and run set per option round, both knobs switched together); empty for a
    knob with no other gain."""
    bare = [dataclasses.replace(k, release_ratio_gain=None) for k in device.knobs]
    device = dataclasses.replace(device, knobs=(bare[0], bare[1]))
    alt = [alternatives(k, d, offer_none)
           for k, d in zip(device.knobs, dropped_release_omega, strict=True)]
    knobs = [i for i in (0, 1) if alt[i]]
    out: tuple[dict[str, float], dict[str, float]] = ({}, {})
    if not knobs:
        return out
    for i, rmse in track(factory, device, config, seed, knobs).items():
        out[i][SHEET] = rmse
    for r in range(max(len(a) for a in alt)):
        mine = [i for i in knobs if r < len(alt[i])]
        changed = [candidate(k, alt[i][r], dropped_release_omega[i]) if i in mine else k
                   for i, k in enumerate(device.knobs)]
        trial = dataclasses.replace(device, knobs=(changed[0] or device.knobs[0],
                                                   changed[1] or device.knobs[1]))
        for i, rmse in track(factory, trial, config, seed, mine).items():
            out[i][alt[i][r]] = rmse
    return out


def with_ratio_gain(device: DeviceModel, config: TsmdConfig, factory: Callable[[], Plant],
                    dropped_release_omega: Sequence[float | None] = (None, None),
                    seed: int = SHEET_UNIT_SEED, offer_none: bool = False) -> DeviceModel:
    """The sheet with each knob's ``release_ratio_gain`` where tracking on its unit chose one
    other than the one it takes as it stands (and the knob's left-out tracked release back
    where that gain uses it; with ``offer_none`` its tracked release left out where that
    tracks better); printed per knob."""
    t0 = time.monotonic()
    scores = measure_gain_scores(factory, device, dropped_release_omega, config, seed,
                                 offer_none=offer_none)
    knobs = list(device.knobs)
    parts = []
    for i, (name, score) in enumerate(zip(("phi1", "phi2"), scores, strict=True)):
        if not score:
            parts.append(f"{name} no other gain")
            continue
        picked = choose(score)
        if picked is not None:
            knobs[i] = candidate(knobs[i], picked, dropped_release_omega[i]) or knobs[i]
        was = default_gain(device.knobs[i]) or "no release_omega"
        parts.append(f"{name} RMSE " + " / ".join(f"{g} {s:.3f}" for g, s in score.items())
                     + f" deg -> {picked or 'as it stands (' + was + ')'}")
    print("  release ratio gain, sheet unit's quick 1-DOF rows (ours): " + "; ".join(parts)
          + f" ({time.monotonic() - t0:.0f} s)")
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))
