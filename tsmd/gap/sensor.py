"""The current-sensor lag's share, measured where a lag is isolated: the rate test's currents.

A lag of tau s at knob speed v delays the current by v * tau deg of knob travel, so the matched
loops at two speeds differ by the lag (:func:`tsmd.gap.loops.lag_design`) whatever the base
physics. Since session 16 a unit is compared with its model's own fast-slow current contrast
(:class:`tsmd.gap.reference.ProductReference` ``currents``) as the rate test compares the tips:
capstan data with the helixbelt simulator, and helixbelt development unit 2 with the capstan
one, named sensor on "none" from the simulator's own current contrast (docs/gap.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.contrast import TestData, collect_tests
from tsmd.gap.data import GapSeries
from tsmd.gap.loops import Loops, contrast_of, lag_design, loop_contrast, loop_shrink, noise_ss
from tsmd.gap.reference import LoopReference, beyond_reference, measured_windows

FloatArray = NDArray[np.float64]


def lag_share(series: Sequence[GapSeries], residuals: Sequence[FloatArray],
              reference: LoopReference | None = None) -> tuple[float, float, float] | None:
    """Share of the rate test's current contrast (fast against slow loops) that a lag of the
    current explains, fitted on one configuration and scored on the other (mean, lowest,
    highest over the held-out configurations); None without such a contrast. With the
    model's ``reference`` of that contrast (since session 16) only what this unit has beyond
    its model's own fast-slow current contrast is explained, as the rate test does for the
    tips; a unit within its model's units' spread has a share of 0."""
    by_config = collect_tests(series, residuals)
    meas = (collect_tests(series, [measured_windows(s) for s in series])
            if reference is not None else {})
    found = [_currents_beyond(d["rate"], meas.get(c, {}).get("rate"), reference)
             for c, d in by_config.items() if "rate" in d]
    loops = [lp for lp in found if lp is not None]
    speeds = _level_speeds(series, "rate")
    if len(loops) < 2 or len(speeds) < 2 or min(speeds) <= 0.0:
        return None
    if reference is not None:
        kept = _within_units(loops, reference)
        if kept is None:
            return 0.0, 0.0, 0.0
        loops = kept
    design = lag_design(speeds)
    shrinks = [loop_shrink(loops[:i] + loops[i + 1:], loops[i], design)
               for i in range(len(loops))]
    finite = [x for x in shrinks if np.isfinite(x)]
    if not finite:
        return None if reference is None else (0.0, 0.0, 0.0)
    return float(np.mean(finite)), min(finite), max(finite)


def _within_units(loops: Sequence[Loops], ref: LoopReference) -> list[Loops] | None:
    """None when the loops (beyond the model's own) lie within its units' spread; else the
    loops with only the reference's noise counted: a unit's own deviation is the same in both
    configurations, so it is no noise to the share, which is scored across them."""
    ss = sum(float((contrast_of(lp) ** 2).sum()) - noise_ss(lp) for lp in loops)
    if ss <= 0.0:
        return None
    return [replace(lp, ref_noise_ss=lp.y.shape[2] * ref.noise_per_point) for lp in loops]


def _currents_beyond(res: TestData, meas: TestData | None, ref: LoopReference | None
                     ) -> Loops | None:
    """One configuration's residual current loops of the rate test, less the model's own."""
    lp = loop_contrast(res.currents, res.levels)
    mp = loop_contrast(meas.currents, meas.levels) if meas is not None else None
    if lp is None or mp is None or ref is None:
        return lp
    return beyond_reference(lp, mp, res.levels, ref)


def _level_speeds(series: Sequence[GapSeries], test: str) -> list[float]:
    """Median knob speed (deg/s) of each level of ``test``, from the recorded motion."""
    speeds: dict[str, list[FloatArray]] = {}
    for s in series:
        if s.segment is None:
            continue
        dt = np.diff(s.t_s, prepend=s.t_s[0] - 1.0)
        v = np.abs(np.diff(s.knob_deg, axis=0, prepend=s.knob_deg[:1])) / dt[:, None]
        for i, seg in enumerate(s.segments):
            if seg.test == test:
                speeds.setdefault(seg.level, []).append(v[s.segment == i].max(axis=1))
    return [float(np.median(np.concatenate(v))) for v in speeds.values()]
