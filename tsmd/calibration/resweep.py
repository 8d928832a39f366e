"""Measure more instead of refusing: which grid points to sweep again, and pooling the result.

After the protocol's sweeps, every parameter of every grid point has an estimate and a 95 %
uncertainty (:mod:`tsmd.calibration.estimate`). A grid point where a parameter's uncertainty
costs more than the gate allows on the tip, or where no half-cycle gave it, is swept again
(``Protocol.resweep_cycles`` more cycles), worst first, while the protocol's re-sweep budget
(``Protocol.resweep_budget_s`` of extra sweeping) lasts; the re-sweep's half-cycles are pooled
with the first sweep's.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

from tsmd.calibration.assemble import KNOB_LABELS, GridPoint
from tsmd.calibration.estimate import Estimate, EstimateOptions
from tsmd.calibration.estimate import point_estimates as estimate_points
from tsmd.calibration.identify import SHORT


@dataclass(frozen=True)
class Uncertain:
    """A grid point the gate does not accept yet, and why."""

    index: int
    """Index into the list of grid points."""
    names: tuple[str, ...]
    worst_tip_cost_deg: float

    def describe(self, points: Sequence[GridPoint]) -> str:
        return f"{points[self.index].name}: {', '.join(SHORT[n] for n in self.names)} uncertain"


def point_estimates(points: Sequence[GridPoint],
                    options: EstimateOptions | None = None) -> list[dict[str, Estimate]]:
    """Estimates for every grid point, the scatter pooled over all of them."""
    return estimate_points([p.result for p in points], options)


def uncertain_points(points: Sequence[GridPoint], omegas: Sequence[float],
                     options: EstimateOptions | None = None) -> list[Uncertain]:
    """Grid points the gate does not accept, the costliest on the tip first."""
    opts = options or EstimateOptions()
    found = []
    for i, est in enumerate(point_estimates(points, opts)):
        omega = omegas[points[i].knob]
        costs = {n: e.tip_cost_deg(omega) for n, e in est.items()}
        bad = tuple(n for n, c in costs.items() if not c <= opts.max_tip_error_deg)
        if bad:
            worst = max(costs[n] for n in bad)
            found.append(Uncertain(i, bad, worst if math.isfinite(worst) else math.inf))
    return sorted(found, key=lambda u: -u.worst_tip_cost_deg)


def pooled(point: GridPoint, again: GridPoint) -> GridPoint:
    """The grid point with a re-sweep's half-cycles pooled in (first recording kept)."""
    return dataclasses.replace(point, result=point.result.merged(again.result))


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
