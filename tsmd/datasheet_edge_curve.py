"""The product's curved-hinge check (``edge_curve``), chosen on the data sheet's own unit.

The check (:mod:`tsmd.calibration.curved_ramp`) lets a knee stand only where it beats a smoothly
bending ramp. Jawcrimp's wall-loaded current bends smoothly past the engagement, and without the
check the fit took a knee 10-12 deg past the edge on some half-cycles and the hinge on others;
on warmgear's real corner the check read the edge 2-3 deg early (development units 1-2: 107 ->
76 of 112 values within 2 deg, docs/calibration.md session 20). So no setting holds for every
product, and which one a product needs is seen where its other constants are measured: the
sheet's unit, tracked. Its fast calibrations with the chosen rules (current only, as every unit
is calibrated) are read twice per half-cycle, with and without the check, from the same
conditioned current, and each dead-zone edge is compared with the tip's edge at that grid point.
What counts is each edge's scatter about its grid point's mean error, not the error itself: the
product's reading offset, measured next from this unit's readings, takes out a steady shift
(jawcrimp's curve start reads 1-2 deg inside the tip's edge), while a reading that flips between
two corners, or strays from one half-cycle to the next, stays in every unit. A knob takes the
check when that scatter falls by more than ``SCATTER_K`` standard errors of the paired
per-half-cycle change (a sampling error, not a target: where the check moves no edge the change
is exactly 0 and the check stays off). On unit 0 (session 21): jawcrimp 2.04 -> 0.19 and
1.54 -> 0.11 deg, on; warmgear 0.49 -> 1.21 and 0.71 -> 1.16, off (its mean |error| fell on phi2,
2.68 -> 1.84: the check there trades a steady shift for scatter); no edge moved on lumped,
screwrod, archwave, helixbelt (docs/calibration.md "Session 21: jawcrimp's edge-curve choice").
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.identify import analyse_half_cycle
from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.protocol import fast_protocol
from tsmd.calibration.run import device_options
from tsmd.config import TsmdConfig
from tsmd.profile import DeviceModel
from tsmd.tracked_calibration import ProtocolRun, play_protocol

Truth = dict[tuple[int, float], dict[str, float]]

SCATTER_K = 2.0
"""The scatter's mean fall must exceed this many standard errors of the paired per-half-cycle
changes (about a 95 % interval excluding no change)."""


@dataclass(frozen=True)
class EdgeCurveScore:
    """One knob's dead-zone edges on the sheet's unit, read without and with the check."""

    knob: int
    half_cycles: int
    changed: int
    """Half-cycles whose edge the check moved."""
    mean_abs_off_deg: float
    """Mean |edge - tip| without the check ..."""
    mean_abs_on_deg: float
    """... and with it."""
    scatter_off_deg: float
    """Mean |edge - tip - its grid point's mean| without the check ..."""
    scatter_on_deg: float
    """... and with it."""
    change_se_deg: float
    """Standard error of the mean paired change in that scatter."""

    @property
    def gain_deg(self) -> float:
        """Scatter without the check minus with it (positive: the check reads steadier)."""
        return self.scatter_off_deg - self.scatter_on_deg

    @property
    def chosen(self) -> bool:
        return self.half_cycles > 1 and self.gain_deg > SCATTER_K * self.change_se_deg > 0.0

    def text(self) -> str:
        return (f"edge - tip without the check |{self.mean_abs_off_deg:.2f}| deg, about its grid "
                f"point's mean |{self.scatter_off_deg:.2f}|; with it |{self.mean_abs_on_deg:.2f}|"
                f", |{self.scatter_on_deg:.2f}| over {self.half_cycles} half-cycles "
                f"({self.changed} moved; se {self.change_se_deg:.2f} deg) -> "
                f"{'on' if self.chosen else 'off'}")


def with_edge_curve(device: DeviceModel, on: tuple[bool, bool]) -> DeviceModel:
    """The sheet with the check on where ``on`` says (per knob; off is absent)."""
    return device.with_knob_flag("edge_curve", on)


EdgeRead = tuple[int, float, str, float, float]
"""(knob, other knob's angle, edge name, edge - tip without the check, the same with it; deg)."""


def edge_pairs(points: Sequence[GridPoint], options: tuple[IdentifyOptions, IdentifyOptions],
               truth: Truth) -> list[EdgeRead]:
    """Per dead-zone edge read by a half-cycle of ``points`` (identified without the check),
    its error against the tip's edge at the same grid point without and with the check; the
    half-cycles of pooled re-sweeps (whose signals are not kept) are left out."""
    out = []
    for p in points:
        tip = truth.get((p.knob, float(p.other_deg)), {})
        opts = dataclasses.replace(options[p.knob], edge_curve=True)
        for h in p.result.data_half_cycles:
            t = tip.get(h.edge_name, math.nan)
            if not (math.isfinite(h.edge_deg) and math.isfinite(t)):
                continue
            on = analyse_half_cycle(p.result.data, h.direction, h.start, h.stop,
                                    h.after_reversal, opts).edge_deg
            if math.isfinite(on):
                out.append((p.knob, float(p.other_deg), h.edge_name, h.edge_deg - t, on - t))
    return out


def about_own_mean(reads: Sequence[EdgeRead]) -> tuple[np.ndarray, np.ndarray]:
    """Each read's error without and with the check minus its grid point's mean error (the
    edge at that other-knob angle over the seeds): what the product's reading offset, measured
    from these same reads next, cannot take out."""
    groups: dict[tuple[int, float, str], list[int]] = {}
    for i, (knob, other, edge, _, _) in enumerate(reads):
        groups.setdefault((knob, other, edge), []).append(i)
    off = np.array([r[3] for r in reads], dtype=float)
    on = np.array([r[4] for r in reads], dtype=float)
    for idx in groups.values():
        off[idx] -= off[idx].mean()
        on[idx] -= on[idx].mean()
    return off, on


def edge_curve_scores(reads: Sequence[EdgeRead]) -> list[EdgeCurveScore]:
    """Each knob's :class:`EdgeCurveScore` from :func:`edge_pairs`."""
    out = []
    for knob in (0, 1):
        mine = [r for r in reads if r[0] == knob]
        off = np.abs([r[3] for r in mine])
        on = np.abs([r[4] for r in mine])
        off_c, on_c = (np.abs(a) for a in about_own_mean(mine))
        n = off.size
        change = off_c - on_c
        se = float(np.std(change, ddof=1) / math.sqrt(n)) if n > 1 else math.nan
        out.append(EdgeCurveScore(
            knob, n, int(np.count_nonzero(np.abs(off - on) > 1e-9)),
            float(np.mean(off)) if n else math.nan, float(np.mean(on)) if n else math.nan,
            float(np.mean(off_c)) if n else math.nan, float(np.mean(on_c)) if n else math.nan,
            se))
    return out


def choose_edge_curve(config: TsmdConfig, device: DeviceModel, truth: Truth,
                      noise_seeds: Sequence[int]
                      ) -> tuple[DeviceModel, list[EdgeCurveScore], list[ProtocolRun]]:
    """The sheet's unit (``config.sim``) calibrated with the fast protocol under ``device``
    without the check, once per noise seed, and each knob's check chosen on its edges.
    (sheet, scores, the runs: made with ``with_edge_curve(device, (False, False))``, so the
    reading offset re-uses them where no knob takes the check)"""
    plain = with_edge_curve(device, (False, False))
    options = device_options(None, plain)
    runs = [play_protocol(config, plain, fast_protocol(), seed) for seed in noise_seeds]
    scores = edge_curve_scores([pair for run in runs
                                for pair in edge_pairs(run.points, options, truth)])
    return with_edge_curve(device, (scores[0].chosen, scores[1].chosen)), scores, runs
