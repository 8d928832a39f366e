"""The diagnosed simulator: plant + linear output map + optional candidate effects, and its fits.

A model evaluation = (1) knob motion through the candidates' input transforms, (2) the plant,
(3) per channel a linear least-squares map onto the measurement (tip: gain + offset; current: the
:func:`~tsmd.gap.simulate.current_regressors`) plus the candidates' extra regressors. Linear
terms are solved exactly on training rows here; the nonlinear ones (plant base parameters,
candidate parameters) are searched in :mod:`tsmd.gap.fit`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.data import GapSeries, Split
from tsmd.gap.simulate import (
    PlantFactory,
    current_regressors,
    eval_grid,
    fit_grid,
    simulate,
    smooth_velocity,
)

CHANNELS: tuple[str, ...] = ("tip1", "tip2", "cur1", "cur2")


@dataclass
class View:
    """Rows of one series on one grid (fit or eval), with what the model needs precomputed."""

    series: GapSeries
    rows: NDArray[np.int64]
    train: NDArray[np.bool_]
    test: NDArray[np.bool_]
    block: NDArray[np.int64]
    vel_deg_s: NDArray[np.float64]
    base_tip: NDArray[np.float64] | None = None
    base_torque: NDArray[np.float64] | None = None

    @property
    def t_s(self) -> NDArray[np.float64]:
        return self.series.t_s[self.rows]

    @property
    def knob_deg(self) -> NDArray[np.float64]:
        return self.series.knob_deg[self.rows]

    @property
    def valid(self) -> NDArray[np.bool_]:
        """(4,): which channels this series measured."""
        return np.array(self.series.channel_valid, dtype=bool)

    @property
    def measured(self) -> NDArray[np.float64]:
        """(n, 4): tip1, tip2, cur1, cur2."""
        return np.column_stack([self.series.tip_deg[self.rows], self.series.current_A[self.rows]])


def build_views(series: Sequence[GapSeries], split: Split, strides: Sequence[int],
                kind: str, held_out_strides: Sequence[int] | None = None) -> list[View]:
    """Views for the fit grid (``kind='fit'``) or an evaluation grid (``'eval'``).

    The evaluation grid holds every ``held_out_strides[i]``-th held-out row (1 = all of them).
    """
    views = []
    ho_strides = held_out_strides or [1] * len(series)
    for s, blk, ho, stride, ho_stride in zip(series, split.block, split.held_out, strides,
                                             ho_strides, strict=True):
        rows = (fit_grid(len(s), stride, s.knob_deg) if kind == "fit"
                else eval_grid(ho, stride, ho_stride, s.knob_deg))
        vel = smooth_velocity(s.t_s, s.knob_deg)
        views.append(View(s, rows, ~ho[rows], ho[rows], blk[rows], vel[rows]))
    return views


class Candidate:
    """A candidate unmodelled effect: a transform around the base simulator.

    Subclasses set the class attributes and override the hooks they need. Every candidate
    reduces to the base simulator at ``neutral`` parameters.
    """

    name: str = ""
    title: str = ""
    physics: str = ""
    param_names: tuple[str, ...] = ()
    lower: tuple[float, ...] = ()
    upper: tuple[float, ...] = ()
    neutral: tuple[float, ...] = ()
    changes_input: bool = False

    def knob(self, theta: NDArray[np.float64], view: View,
             knob_deg: NDArray[np.float64]) -> NDArray[np.float64]:
        """Knob angles the plant sees (input-stage candidates)."""
        return knob_deg

    def tip_extra(self, theta: NDArray[np.float64], view: View,
                  knob: int) -> list[NDArray[np.float64]]:
        """Extra linear regressors for tip ``knob``."""
        return []

    def current_extra(self, theta: NDArray[np.float64], view: View,
                      knob: int) -> list[NDArray[np.float64]]:
        """Extra linear regressors for current ``knob``."""
        return []

    def current_filter(self, theta: NDArray[np.float64], view: View,
                       regs: NDArray[np.float64]) -> NDArray[np.float64]:
        """Transform of the current regressors (e.g. sensor dynamics)."""
        return regs


Active = Sequence[tuple[Candidate, NDArray[np.float64]]]


@dataclass
class Prediction:
    """Model output on every view, the linear coefficients, and the weighted training cost."""

    values: list[NDArray[np.float64]]
    coefs: list[NDArray[np.float64]]
    cost: float
    channel_cost: NDArray[np.float64]


@dataclass
class Evaluator:
    """Evaluates models on a set of views; caches the base plant simulation."""

    factory: PlantFactory
    plant_params: dict[str, Any]
    noise_var: NDArray[np.float64]
    v0_deg_s: NDArray[np.float64]
    evaluations: int = 0
    sim_rows: int = 0
    _base_cache: dict[int, tuple[NDArray[np.float64], NDArray[np.float64]]] = field(
        default_factory=dict)

    def sim(self, view: View,
            knob_deg: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        plant = self.factory(self.plant_params)
        self.sim_rows += len(view.rows)
        return simulate(plant, view.t_s, knob_deg)

    def base(self, view: View) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Base simulation of a view (cached; also stored on the view for the candidates)."""
        key = id(view)
        if key not in self._base_cache:
            self._base_cache[key] = self.sim(view, view.knob_deg)
            view.base_tip, view.base_torque = self._base_cache[key]
        return self._base_cache[key]

    def regressors(self, view: View, tip_sim: NDArray[np.float64],
                   torque: NDArray[np.float64], active: Active) -> list[NDArray[np.float64]]:
        """Per channel the (n, k) regressor matrix."""
        out = []
        for j in range(2):
            cols = [tip_sim[:, j], np.ones(len(tip_sim))]
            for cand, theta in active:
                cols.extend(cand.tip_extra(theta, view, j))
            out.append(np.column_stack(cols))
        for j in range(2):
            regs = current_regressors(torque[:, j], view.vel_deg_s[:, j], float(self.v0_deg_s[j]))
            for cand, theta in active:
                regs = cand.current_filter(theta, view, regs)
            extra = [c for cand, theta in active for c in cand.current_extra(theta, view, j)]
            if extra:
                regs = np.column_stack([regs, *extra])
            out.append(regs)
        return out

    def design(self, views: Sequence[View], active: Active) -> list[list[NDArray[np.float64]]]:
        designs = []
        for view in views:
            knob = view.knob_deg
            changed = False
            for cand, theta in active:
                if cand.changes_input:
                    self.base(view)
                    knob = cand.knob(theta, view, knob)
                    changed = True
            tip_sim, torque = self.sim(view, knob) if changed else self.base(view)
            designs.append(self.regressors(view, tip_sim, torque, active))
        return designs

    def predict(self, views: Sequence[View], active: Active,
                coefs: list[NDArray[np.float64]] | None = None) -> Prediction:
        """Fit the linear terms on training rows (unless ``coefs`` given) and predict all rows."""
        self.evaluations += 1
        designs = self.design(views, active)
        if coefs is None:
            coefs = []
            for c in range(4):
                used = [(d, v) for d, v in zip(designs, views, strict=True) if v.valid[c]]
                if not used:
                    coefs.append(np.zeros(designs[0][c].shape[1]))
                    continue
                a = np.vstack([d[c][v.train] for d, v in used])
                b = np.concatenate([v.measured[v.train, c] for _, v in used])
                scale = np.maximum(np.abs(a).max(axis=0), 1e-12)
                sol, *_ = np.linalg.lstsq(a / scale, b, rcond=None)
                coefs.append(sol / scale)
        values = [np.column_stack([d[c] @ coefs[c] for c in range(4)]) for d in designs]
        channel = np.zeros(4)
        for v, y in zip(views, values, strict=True):
            r = (y - v.measured)[v.train] * v.valid
            channel += np.sum(r * r, axis=0) / self.noise_var
        return Prediction(values, coefs, float(channel.sum()), channel)
