"""The product's play step (``backlash_play_step``), chosen on the data sheet's own unit.

A release rule reads where the current stops swinging after a reversal; on a handle whose play
opens while its drum stands (planetwist), the tip lets go only where the play closes, some
7-15 knob deg later, and a reading offset measured on the sheet's unit carries that unit's play
to every unit (docs/calibration.md, "Session 24: planetwist's backlash"). Whether the current
marks the play's end is seen on the sheet's unit, tracked: its fast calibrations under the
chosen rules (current only) are read once more per after-reversal half-cycle for a lone step
in the flat current (:func:`tsmd.calibration.identify.play_step_at`), and each step and each
rule end is compared with the tip's backlash at that grid point. A knob takes the step where
it shows in at least ``MIN_FOUND_SHARE`` of the half-cycles, lies within the accuracy target of
the tip in at least ``MIN_WITHIN_SHARE`` of those, and reads the tip closer on average than the
rule's own end does: the step then is the tip's release as the current sees it, on every unit
that has one, where the offset would only be the sheet unit's distance to it. Where no step
shows (a handle without such play, a step buried in noise) the knob keeps its rule.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tsmd.calibration.identify import play_step_at
from tsmd.calibration.run import device_options
from tsmd.profile import DeviceModel
from tsmd.tracked_calibration import TARGET_DEG, ProtocolRun

Truth = dict[tuple[int, float], dict[str, float]]

MIN_FOUND_SHARE = 0.9
"""A step must show in this share of the sheet unit's half-cycles: a product's feature, not a
chance excursion in a few."""
MIN_WITHIN_SHARE = 0.9
"""... and lie within ``TARGET_DEG`` of the tip's backlash in this share of those."""


@dataclass(frozen=True)
class PlayStepScore:
    """One knob's backlashes on the sheet's unit: the rule's ends and the play steps."""

    knob: int
    half_cycles: int
    found: int
    """Half-cycles whose current shows a step."""
    within: int
    """Steps within ``TARGET_DEG`` of the tip's backlash."""
    step_mae_deg: float
    """Mean |step - tip| over the steps found ..."""
    rule_mae_deg: float
    """... and mean |rule's end - tip| over the same half-cycles (no reading offset)."""

    @property
    def chosen(self) -> bool:
        return (self.half_cycles > 0 and self.found >= MIN_FOUND_SHARE * self.half_cycles
                and self.within >= MIN_WITHIN_SHARE * self.found
                and self.step_mae_deg < self.rule_mae_deg)

    def text(self) -> str:
        if self.found == 0:
            return f"step in 0/{self.half_cycles} half-cycles -> rule"
        return (f"step in {self.found}/{self.half_cycles} half-cycles, {self.within} within "
                f"{TARGET_DEG:g} deg of the tip, mean |error| {self.step_mae_deg:.2f} deg "
                f"against the rule's {self.rule_mae_deg:.2f} -> "
                f"{'step' if self.chosen else 'rule'}")


def play_step_scores(runs: Sequence[ProtocolRun], device: DeviceModel, truth: Truth
                     ) -> tuple[PlayStepScore, PlayStepScore]:
    """Each knob's steps and rule ends on the sheet unit's calibrations ``runs`` (made with
    ``device``, without the step) against the tip's backlash at each grid point."""
    opts = device_options(None, device)
    out = []
    for knob in (0, 1):
        step_err: list[float] = []
        rule_err: list[float] = []
        halves = 0
        for run in runs:
            for p in run.points:
                if p.knob != knob:
                    continue
                tip = truth.get((p.knob, float(p.other_deg)), {})
                for h in p.result.data_half_cycles:
                    ref = tip.get(h.backlash_name, math.nan)
                    if not (h.after_reversal and math.isfinite(h.backlash_deg)
                            and math.isfinite(ref)):
                        continue
                    halves += 1
                    _, grid, k = play_step_at(p.result.data, h, opts[knob])
                    if k is not None:
                        step_err.append(abs(float(grid[k] - grid[0]) - ref))
                        rule_err.append(abs(h.backlash_deg - ref))
        e = np.asarray(step_err)
        out.append(PlayStepScore(
            knob, halves, e.size, int(np.sum(e <= TARGET_DEG)),
            float(np.mean(e)) if e.size else math.nan,
            float(np.mean(rule_err)) if rule_err else math.nan))
    return out[0], out[1]


def with_play_step(device: DeviceModel, scores: Sequence[PlayStepScore]) -> DeviceModel:
    """The sheet with ``backlash_play_step`` on the knobs whose score chose it (absent on the
    others)."""
    knobs = tuple(dataclasses.replace(k, backlash_play_step=True if s.chosen else None)
                  for k, s in zip(device.knobs, scores, strict=True))
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))
