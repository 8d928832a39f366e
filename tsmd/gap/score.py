"""How a self-test is scored: each case's verdict against the effect put in, both ways.

An injected effect may leave less on the recorded signals than their noise (helixbelt's 120 deg
sheath bend moves its tip 0.05 deg against 0.1 deg of tracker noise, docs/gap.md "Session
15"): then "none" is the right reading, and naming the effect would be luck. Every case
carries the effect's footprint (:mod:`tsmd.gap.detectable`); the summary gives the score as
the effect was put in (*strict*: such a case counts as a miss unless named) and as detectable
(*below detection expected none*: such a case is right when nothing is named, and is not
counted among the identified effects), so nobody is fooled by either.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass
class SelftestCase:
    case: str
    duration_s: float
    seed: int
    expected: str | None
    verdict: str
    top: str | None
    share: float | None
    tip_rmse_before: float
    tip_rmse_after: float | None
    cur_rmse_before: float
    cur_rmse_after: float | None
    wall_s: float
    excess_shrink: float | None = None
    """Held-out: share of the remaining excess the named effect removes (signature method)."""
    physics_tip_rmse: float | None = None
    """Held-out tip RMSE of the physics simulator alone (the base mismatch, signature method)."""
    footprint_tip_deg: float | None = None
    """What the injected effect moves the true tip (RMS, effect on minus off; None: not
    measured)."""
    footprint_cur_A: float | None = None
    """The same for the true motor current as the sensor reads it (its lag included)."""
    detectable: bool | None = None
    """Whether the footprint reaches one sample's noise on the tip or the current (None: not
    measured, taken as detectable)."""

    within_spread: str | None = None
    """The effect the diagnosis found beyond the model's mean unit but inside its units'
    spread, when it named nothing else (None: no such reading)."""

    @property
    def correct(self) -> bool:
        """Top-1 against the effect put in (strict)."""
        return self.top == self.expected

    @property
    def expected_detectable(self) -> str | None:
        """What a diagnosis can name: the effect put in, or none when it is below detection."""
        return None if self.detectable is False else self.expected

    @property
    def correct_detectable(self) -> bool:
        """Top-1 against what the data can show (:attr:`expected_detectable`)."""
        return self.top == self.expected_detectable

    @property
    def spread_reading(self) -> bool:
        """Nothing named, the effect put in read as inside the model's units' spread: the
        verdict says the effect may be there but cannot be told from unit scatter."""
        return (self.top is None and self.expected is not None
                and self.within_spread == self.expected)


@dataclass
class SelftestResult:
    cases: list[SelftestCase] = field(default_factory=list)

    def confusion(self) -> dict[str, dict[str, int]]:
        """Rows: effect put in the data; columns: top-1 diagnosis ('none' = nothing significant)."""
        out: dict[str, dict[str, int]] = {}
        for c in self.cases:
            row = out.setdefault(c.case, {})
            key = c.top or "none"
            row[key] = row.get(key, 0) + 1
        return out

    def summary(self) -> dict[str, Any]:
        effect_cases = [c for c in self.cases if c.expected is not None]
        null_cases = [c for c in self.cases if c.expected is None]
        shown = [c for c in effect_cases if c.detectable is not False]
        below = [c for c in effect_cases if c.detectable is False]
        shrink = [1 - c.tip_rmse_after / c.tip_rmse_before for c in effect_cases
                  if c.correct and c.tip_rmse_after is not None and c.tip_rmse_before > 0]
        cur_shrink = [1 - c.cur_rmse_after / c.cur_rmse_before for c in effect_cases
                      if c.correct and c.cur_rmse_after is not None and c.cur_rmse_before > 0]
        return {
            "top1_accuracy": (sum(c.correct for c in effect_cases) / len(effect_cases)
                              if effect_cases else float("nan")),
            "n_effect_cases": len(effect_cases),
            "false_alarms": sum(c.top is not None for c in null_cases),
            "n_null_cases": len(null_cases),
            "top1_accuracy_detectable": (sum(c.correct for c in shown) / len(shown)
                                         if shown else float("nan")),
            "n_detectable_effect_cases": len(shown),
            "n_below_detection": len(below),
            "below_detection_read_none": sum(c.top is None for c in below),
            "within_spread_own_effect": sum(c.spread_reading for c in effect_cases),
            "within_spread_null": sum(c.top is None and c.within_spread is not None
                                      for c in null_cases),
            "median_tip_rmse_shrink_when_correct": float(np.median(shrink)) if shrink
            else float("nan"),
            "median_current_rmse_shrink_when_correct": float(np.median(cur_shrink))
            if cur_shrink else float("nan"),
            "median_wall_s": _median([c.wall_s for c in self.cases]),
            "median_excess_shrink_when_correct": _median(
                [c.excess_shrink for c in effect_cases if c.correct]),
            "worst_excess_shrink_when_correct": _min(
                [c.excess_shrink for c in effect_cases if c.correct]),
        }


def _median(values: Sequence[float | None]) -> float:
    found = [v for v in values if v is not None]
    return float(np.median(found)) if found else float("nan")


def _min(values: Sequence[float | None]) -> float:
    found = [v for v in values if v is not None]
    return float(np.min(found)) if found else float("nan")


def _footprint(c: SelftestCase) -> str:
    if c.footprint_tip_deg is None or c.footprint_cur_A is None:
        return "-"
    mark = "" if c.detectable is not False else " (below noise)"
    return f"{c.footprint_tip_deg:.3f} deg / {1e3 * c.footprint_cur_A:.1f} mA{mark}"


def selftest_markdown(result: SelftestResult) -> str:
    s = result.summary()
    n_right = sum(c.correct for c in result.cases if c.expected)
    lines = ["| figure | value |", "| --- | ---: |",
             f"| top-1 accuracy (effect cases, strict) | {s['top1_accuracy']:.0%} "
             f"({n_right}/{s['n_effect_cases']}) |"]
    if s["n_below_detection"]:
        n_shown = sum(c.correct for c in result.cases
                      if c.expected and c.detectable is not False)
        lines += [f"| top-1 accuracy (effect cases above the noise) | "
                  f"{s['top1_accuracy_detectable']:.0%} "
                  f"({n_shown}/{s['n_detectable_effect_cases']}) |",
                  f"| effect cases below detection read none (expected) | "
                  f"{s['below_detection_read_none']}/{s['n_below_detection']} |"]
    if s["within_spread_own_effect"] or s["within_spread_null"]:
        lines += [f"| effect cases read 'within the model's units' spread' (not counted above) | "
                  f"{s['within_spread_own_effect']}/{s['n_effect_cases']} |",
                  f"| no-effect cases read 'within the model's units' spread' (no alarm) | "
                  f"{s['within_spread_null']}/{s['n_null_cases']} |"]
    lines += [f"| false alarms (no-effect cases) | {s['false_alarms']}/{s['n_null_cases']} |",
              f"| median held-out tip RMSE shrink, correct cases | "
              f"{s['median_tip_rmse_shrink_when_correct']:.0%} |",
              f"| median held-out current RMSE shrink, correct cases | "
              f"{s['median_current_rmse_shrink_when_correct']:.0%} |",
              f"| median / worst held-out shrink of the named effect's excess, correct cases | "
              f"{s['median_excess_shrink_when_correct']:.0%} / "
              f"{s['worst_excess_shrink_when_correct']:.0%} |",
              f"| median wall time per diagnosis | {s['median_wall_s']:.1f} s |", "",
              "Confusion matrix (rows: effect in the data; columns: top-1 diagnosis):", ""]
    conf = result.confusion()
    cols = sorted({k for row in conf.values() for k in row} | {"none"})
    lines += ["| data \\ diagnosis | " + " | ".join(cols) + " |",
              "| --- |" + " ---: |" * len(cols)]
    for case, row in conf.items():
        lines.append(f"| {case} | " + " | ".join(str(row.get(c, 0)) for c in cols) + " |")
    lines += ["", "| case | size (s) | seed | verdict | top-1 | share | tip RMSE before -> after "
              "(deg) | current RMSE before -> after (A) | effect's footprint (tip / current) "
              "| wall (s) |",
              "| --- | ---: | ---: | --- | --- | ---: | --- | --- | --- | ---: |"]
    for c in result.cases:
        after_tip = "-" if c.tip_rmse_after is None else f"{c.tip_rmse_after:.3f}"
        after_cur = "-" if c.cur_rmse_after is None else f"{c.cur_rmse_after:.4f}"
        share = "-" if c.share is None else f"{c.share:.0%}"
        lines.append(f"| {c.case} | {c.duration_s:.0f} | {c.seed} | {c.verdict} | "
                     f"{c.top or 'none'} | {share} | {c.tip_rmse_before:.3f} -> {after_tip} | "
                     f"{c.cur_rmse_before:.4f} -> {after_cur} | {_footprint(c)} | "
                     f"{c.wall_s:.1f} |")
    return "\n".join(lines)
