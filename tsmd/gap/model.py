"""The diagnosed simulator: plant + linear output map + optional candidate effects, and its fits.

A model evaluation = (1) knob motion through the candidates' input transforms, (2) the plant,
(3) per channel a linear least-squares map onto the measurement (tip: gain + offset; current: the
:class:`~tsmd.gap.simulate.CurrentMap` regressors) plus the candidates' extra regressors. Linear
terms are solved exactly on training rows; nonlinear ones (plant base parameters, candidate
parameters) by a bounded derivative-free search with a small evaluation budget.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy import optimize

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
    def measured(self) -> NDArray[np.float64]:
        """(n, 4): tip1, tip2, cur1, cur2."""
        return np.column_stack([self.series.tip_deg[self.rows], self.series.current_A[self.rows]])


def build_views(series: Sequence[GapSeries], split: Split, strides: Sequence[int],
                kind: str) -> list[View]:
    """Views for the fit grid (``kind='fit'``) or the evaluation grid (``'eval'``)."""
    views = []
    for s, blk, ho, stride in zip(series, split.block, split.held_out, strides, strict=True):
        rows = fit_grid(len(s), stride) if kind == "fit" else eval_grid(ho, stride)
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


@dataclass
class Evaluator:
    """Evaluates models on a set of views; caches the base plant simulation."""

    factory: PlantFactory
    plant_params: dict[str, float]
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
                a = np.vstack([d[c][v.train] for d, v in zip(designs, views, strict=True)])
                b = np.concatenate([v.measured[v.train, c] for v in views])
                scale = np.maximum(np.abs(a).max(axis=0), 1e-12)
                sol, *_ = np.linalg.lstsq(a / scale, b, rcond=None)
                coefs.append(sol / scale)
        values = [np.column_stack([d[c] @ coefs[c] for c in range(4)]) for d in designs]
        cost = 0.0
        for v, y in zip(views, values, strict=True):
            r = (y - v.measured)[v.train]
            cost += float(np.sum(r * r / self.noise_var))
        return Prediction(values, coefs, cost)


def _search(cost: Callable[[NDArray[np.float64]], float], lower: NDArray[np.float64],
            upper: NDArray[np.float64], start: NDArray[np.float64],
            max_evals: int) -> tuple[NDArray[np.float64], float]:
    """Bounded derivative-free minimum of ``cost``; never worse than ``start``."""
    span = np.where(upper > lower, upper - lower, 1.0)
    x0 = np.clip((start - lower) / span, 0.0, 1.0)
    best_u = [x0.copy()]
    best_cost = [cost(start)]

    def scaled(u: NDArray[np.float64]) -> float:
        u = np.clip(np.atleast_1d(u), 0.0, 1.0)
        value = cost(lower + u * span)
        if value < best_cost[0]:
            best_u[0], best_cost[0] = u.copy(), value
        return value

    if len(x0) == 1:
        optimize.minimize_scalar(lambda u: scaled(np.array([u])), bounds=(0.0, 1.0),
                                 method="bounded",
                                 options={"maxiter": max_evals, "xatol": 2e-3})
    else:
        optimize.minimize(scaled, x0, method="Powell", bounds=[(0.0, 1.0)] * len(x0),
                          options={"maxfev": max_evals, "xtol": 2e-3, "ftol": 1e-4})
    return lower + best_u[0] * span, float(best_cost[0])


@dataclass(frozen=True)
class ParamSpec:
    """A plant base parameter to fit: factory keyword and its bounds."""

    name: str
    lower: float
    upper: float


def fit_base(evaluator: Evaluator, views: Sequence[View], specs: Sequence[ParamSpec],
             max_evals: int) -> tuple[dict[str, float], float]:
    """Fit the plant's base parameters on training rows; sets ``evaluator.plant_params``."""
    params = dict(evaluator.plant_params)
    if not specs:
        return params, evaluator.predict(views, []).cost
    lower = np.array([s.lower for s in specs])
    upper = np.array([s.upper for s in specs])
    start = np.array([float(params.get(s.name, 0.5 * (s.lower + s.upper))) for s in specs])
    start = np.clip(start, lower, upper)

    def cost(x: NDArray[np.float64]) -> float:
        trial = {**params, **{s.name: float(v) for s, v in zip(specs, x, strict=True)}}
        evaluator.plant_params = trial
        evaluator._base_cache.clear()
        return evaluator.predict(views, []).cost

    x, best = _search(cost, lower, upper, start, max_evals)
    params.update({s.name: float(v) for s, v in zip(specs, x, strict=True)})
    evaluator.plant_params = params
    evaluator._base_cache.clear()
    return params, best


def fit_candidate(evaluator: Evaluator, views: Sequence[View], cand: Candidate,
                  fixed: Active = (), max_evals: int = 12) -> tuple[NDArray[np.float64], float]:
    """Fit one candidate's nonlinear parameters on training rows (plant parameters fixed)."""
    if not cand.param_names:
        theta = np.zeros(0)
        return theta, evaluator.predict(views, [*fixed, (cand, theta)]).cost
    lower = np.array(cand.lower, dtype=float)
    upper = np.array(cand.upper, dtype=float)

    def cost(x: NDArray[np.float64]) -> float:
        return evaluator.predict(views, [*fixed, (cand, x)]).cost

    return _search(cost, lower, upper, np.array(cand.neutral, dtype=float), max_evals)
