"""Measure more instead of refusing: which grid points to sweep again, and pooling the result.

After the protocol's sweeps, every parameter of every grid point has an estimate and a 95 %
uncertainty (:mod:`tsmd.calibration.estimate`). A grid point where a parameter's uncertainty
costs more than the gate allows on the tip, or where no half-cycle gave it, is a candidate for
another sweep (``Protocol.resweep_cycles`` more cycles) while the protocol's re-sweep budget
(``Protocol.resweep_budget_s`` of extra sweeping) lasts; the re-sweep's half-cycles are pooled
with the first sweep's. The budget is small (the fast protocol's buys two cycles), so it goes
where it removes the most tip cost over the gate, not to the worst point: a point already swept
again gains less from a third sweep than one still on its first (its cost falls as 1/sqrt(n)).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from tsmd.calibration.assemble import KNOB_LABELS, GridPoint
from tsmd.calibration.estimate import Estimate, EstimateOptions
from tsmd.calibration.estimate import point_estimates as estimate_points
from tsmd.calibration.sweep_result import SHORT


@dataclass(frozen=True)
class Uncertain:
    """A grid point the gate does not accept yet, and why."""

    index: int
    """Index into the list of grid points."""
    names: tuple[str, ...]
    worst_tip_cost_deg: float
    gain_deg: float = math.inf
    """Tip cost over the gate, summed over the point's parameters, that one more re-sweep is
    expected to remove (infinite where a parameter has no value yet)."""

    def describe(self, points: Sequence[GridPoint]) -> str:
        return f"{points[self.index].name}: {', '.join(SHORT[n] for n in self.names)} uncertain"


def point_estimates(points: Sequence[GridPoint],
                    options: EstimateOptions | None = None) -> list[dict[str, Estimate]]:
    """Estimates for every grid point, the scatter pooled over all of them."""
    return estimate_points([p.result for p in points], options)


def resweep_gain_deg(estimates: dict[str, Estimate], omega: float, more: int,
                     max_tip_error_deg: float) -> float:
    """Tip cost over ``max_tip_error_deg`` that ``more`` half-cycles per parameter are expected
    to remove, summed over the parameters (infinite where one has no value)."""
    gain = 0.0
    for e in estimates.values():
        now = e.tip_cost_deg(omega)
        if not math.isfinite(now):
            return math.inf
        after = e.tip_cost_with_deg(omega, more)
        gain += max(now - max_tip_error_deg, 0.0) - max(after - max_tip_error_deg, 0.0)
    return gain


def uncertain_points(points: Sequence[GridPoint], omegas: Sequence[float],
                     options: EstimateOptions | None = None,
                     more_half_cycles: int = 1) -> list[Uncertain]:
    """Grid points the gate does not accept, the one a re-sweep of ``more_half_cycles`` per
    parameter helps most first (ties: the costliest)."""
    opts = options or EstimateOptions()
    found = []
    for i, est in enumerate(point_estimates(points, opts)):
        omega = omegas[points[i].knob]
        # a backlash the current does not show is not narrowed by sweeping again
        costs = {n: e.tip_cost_deg(omega) for n, e in est.items()
                 if n not in points[i].result.unseen}
        bad = tuple(n for n, c in costs.items() if not c <= opts.max_tip_error_deg)
        if bad:
            worst = max(costs[n] for n in bad)
            gain = resweep_gain_deg(est, omega, more_half_cycles, opts.max_tip_error_deg)
            found.append(Uncertain(i, bad, worst if math.isfinite(worst) else math.inf, gain))
    return sorted(found, key=lambda u: (-u.gain_deg, -u.worst_tip_cost_deg))


def refusing(todo: Sequence[Uncertain], refuse_tip_error_deg: float) -> list[Uncertain]:
    """The uncertain points that would refuse the calibration, the costliest on the tip first."""
    return sorted((u for u in todo if u.worst_tip_cost_deg > refuse_tip_error_deg),
                  key=lambda u: -u.worst_tip_cost_deg)


@dataclass(frozen=True)
class Choice:
    """What to sweep again next: a point (rescue: beyond the re-sweep budget, because it would
    refuse the calibration), or nothing, with the budget that ran out."""

    point: Uncertain | None
    rescue: bool
    budget_s: float


def choose_resweep(todo: Sequence[Uncertain], spent_s: float, duration_s: Callable[[int], float],
                   resweep_budget_s: float, rescue_budget_s: float,
                   refuse_tip_error_deg: float) -> Choice:
    """The next re-sweep: the first of ``todo`` while the re-sweep budget pays for it
    (``duration_s`` of a point's re-sweep, ``spent_s`` so far); beyond it, the costliest point
    that would refuse the calibration while the rescue budget lasts; else none."""
    if spent_s + duration_s(todo[0].index) <= resweep_budget_s + 1e-6:
        return Choice(todo[0], False, resweep_budget_s)
    rescued = refusing(todo, refuse_tip_error_deg)
    if not rescued:
        return Choice(None, False, resweep_budget_s)
    budget_s = resweep_budget_s + rescue_budget_s
    if spent_s + duration_s(rescued[0].index) > budget_s + 1e-6:
        return Choice(None, True, budget_s)
    return Choice(rescued[0], True, budget_s)


def budget_spent_note(points: Sequence[GridPoint], todo: Sequence[Uncertain],
                      budget_s: float) -> str:
    """One line: the re-sweep budget is spent and these grid points are still over the gate
    (the quality check then warns or refuses by their tip cost)."""
    still = "; ".join(f"{u.describe(points)} (up to {u.worst_tip_cost_deg:.1f} deg on the tip)"
                      for u in todo)
    return f"re-sweep budget ({budget_s:.0f} s) spent; still over the gate: {still}"


def pooled(point: GridPoint, again: GridPoint) -> GridPoint:
    """The grid point with a re-sweep's half-cycles pooled in (first recording kept), in both
    frames (reported and our compensator's)."""
    model = None
    if point.model_result is not None or again.model_result is not None:
        first, second = point.in_model_frame(), again.in_model_frame()
        model = first.result.merged(second.result)
    return dataclasses.replace(point, result=point.result.merged(again.result),
                               model_result=model)


def uncertainty_table(points: Sequence[GridPoint],
                      options: EstimateOptions | None = None) -> str:
    """Markdown: each grid point's estimates with their 95 % half-widths and half-cycle counts."""
    head = ["sweep", *(f"{SHORT[n]} (deg)" for n in SHORT), "re-sweeps"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for p, est in zip(points, point_estimates(points, options), strict=True):
        cells = [f"{KNOB_LABELS[p.knob]}, other {p.other_deg:+.0f}"]
        for name in SHORT:
            e = est[name]
            if e.n == 0:
                cells.append("-")
            elif math.isfinite(e.u95_deg):
                cells.append(f"{e.value:.1f} +- {e.u95_deg:.1f} (n={e.n})")
            else:
                cells.append(f"{e.value:.1f} +- ? (n=1)")
        cells.append(str(p.result.resweeps))
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def pool_repeats(points: Sequence[GridPoint]) -> list[GridPoint]:
    """Logged sweeps of the same grid point (knob and other-knob angle) pooled into one, in
    the order their grid points first appear (repeated acquisitions are re-sweeps)."""
    out: list[GridPoint] = []
    where: dict[tuple[int, float], int] = {}
    for p in points:
        key = (p.knob, round(float(p.other_deg), 6))
        if key in where:
            out[where[key]] = pooled(out[where[key]], p)
        else:
            where[key] = len(out)
            out.append(p)
    return out
