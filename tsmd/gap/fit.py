"""Fits of the nonlinear terms: plant base parameters and candidate-effect parameters.

The linear output maps are solved exactly by :class:`~tsmd.gap.model.Evaluator` at every
evaluation; what is left is a handful of bounded nonlinear parameters, each evaluation a full
replay of the plant, so the searches here are derivative-free and run on a small budget.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Generator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import optimize

from tsmd.gap.model import Active, Candidate, Evaluator, Prediction, View


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
    """A plant base parameter to fit: factory keyword path, bounds, and the knob it belongs to.

    ``name`` may be a dotted path into nested parameters (``knobs.0.slack_pos_mm``: key
    ``knobs``, list item 0, key ``slack_pos_mm``). Paths joined by ``+`` make a *move*: all of
    them shift together by the value (bounds are shift bounds); each path must also be a spec
    of its own. Moves let the coordinate search go along a valley (both slacks at once).
    ``knob`` (0 or 1) says whose channels (tip and current of that knob) judge it; ``None`` =
    all channels.
    """

    name: str
    lower: float
    upper: float
    knob: int | None = None


def set_param(params: dict[str, Any], path: str, value: float) -> dict[str, Any]:
    """A copy of ``params`` with the dotted ``path`` set to ``value`` (lists/dicts created)."""
    out = copy.deepcopy(params)
    keys = path.split(".")
    node: Any = out
    for i, key in enumerate(keys):
        last = i == len(keys) - 1
        nxt = keys[i + 1] if not last else None
        if isinstance(node, list):
            idx = int(key)
            while len(node) <= idx:
                node.append({})
            if last:
                node[idx] = value
            else:
                if not isinstance(node[idx], dict | list):
                    node[idx] = [] if nxt is not None and nxt.isdigit() else {}
                node = node[idx]
        else:
            if last:
                node[key] = value
            else:
                if key not in node or not isinstance(node[key], dict | list):
                    node[key] = [] if nxt is not None and nxt.isdigit() else {}
                node = node[key]
    return out


def get_param(params: dict[str, Any], path: str) -> float | None:
    node: Any = params
    for key in path.split("."):
        try:
            node = node[int(key)] if isinstance(node, list) else node[key]
        except (KeyError, IndexError, ValueError, TypeError):
            return None
    return float(node) if isinstance(node, int | float) else None


def _groups(specs: Sequence[ParamSpec]) -> list[list[ParamSpec]]:
    """Specs searched together: the i-th spec of knob 0 with the i-th of knob 1; others alone."""
    per_knob: dict[int, list[ParamSpec]] = {0: [], 1: []}
    groups: list[list[ParamSpec]] = []
    for s in specs:
        if s.knob in (0, 1):
            per_knob[int(s.knob)].append(s)
        else:
            groups.append([s])
    for i in range(max(len(per_knob[0]), len(per_knob[1]))):
        groups.append([lst[i] for lst in per_knob.values() if i < len(lst)])
    return groups


def _vertex(x: NDArray[np.float64], y: NDArray[np.float64], k: int) -> float:
    """Minimum of the parabola through the grid minimum ``k`` and its neighbours."""
    if k == 0 or k == len(x) - 1:
        return float(x[k])
    x0, x1, x2 = x[k - 1], x[k], x[k + 1]
    y0, y1, y2 = y[k - 1], y[k], y[k + 1]
    denom = (x0 - x1) * (x0 - x2) * (x1 - x2)
    a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / denom
    b = (x2**2 * (y0 - y1) + x1**2 * (y2 - y0) + x0**2 * (y1 - y2)) / denom
    if a <= 0:
        return float(x1)
    return float(np.clip(-b / (2 * a), x0, x2))


def fit_base(evaluator: Evaluator, views: Sequence[View], specs: Sequence[ParamSpec],
             max_evals: int, active: Active = (), width: float | None = None,
             coarse_first: bool = True) -> tuple[dict[str, Any], float]:
    """Fit the plant's base parameters on training rows; sets ``evaluator.plant_params``.

    Coordinate search: each group (a parameter, for both knobs at once) is tried at 5 points
    across its bounds (or +-``width`` around the starting value), later at two
    points either side of the current value; each knob takes the vertex of the parabola through
    its best point and neighbours (judged on its own channels) and the interval halves (or, when
    the best point is at its edge, moves on with the same width). Knob
    parameters mostly act on their own knob, so one plant run tunes both knobs. ``active``
    candidates are part of the model while fitting (joint refinement); ``width`` and
    ``coarse_first`` set the first interval and whether it starts with the 5-point sweep.
    """
    params = copy.deepcopy(evaluator.plant_params)
    if not specs:
        evaluator._base_cache.clear()
        return params, evaluator.predict(views, active).cost
    plain = {s.name: s for s in specs if "+" not in s.name}
    for s in specs:
        missing = [p for p in s.name.split("+") if "+" in s.name and p not in plain]
        if missing:
            raise ValueError(f"move {s.name!r}: {missing} must also be fitted on their own")
    value = {n: float(np.clip(get_param(params, n) or 0.5 * (s.lower + s.upper),
                              s.lower, s.upper)) for n, s in plain.items()}

    def centre(s: ParamSpec) -> float:
        return value[s.name] if s.name in plain else 0.0

    # first interval: the bounds, or +-width (relative) around the starting value
    lo: dict[str, float] = {}
    hi: dict[str, float] = {}
    for s in specs:
        c = centre(s)
        if width is None or s.name not in plain:
            lo[s.name], hi[s.name] = s.lower, s.upper
        else:
            lo[s.name] = max(s.lower, c - width * abs(c))
            hi[s.name] = min(s.upper, c + width * abs(c))
        if hi[s.name] - lo[s.name] < 1e-9:
            lo[s.name], hi[s.name] = s.lower, s.upper

    def place(vals: dict[str, float], s: ParamSpec, x: float) -> None:
        """Put spec ``s`` at ``x`` (a value, or for a move the shift of all its paths)."""
        if s.name in plain:
            vals[s.name] = x
            return
        for path in s.name.split("+"):
            ps = plain[path]
            vals[path] = float(np.clip(value[path] + x, ps.lower, ps.upper))

    def build(vals: dict[str, float]) -> dict[str, Any]:
        out = params
        for name, v in vals.items():
            out = set_param(out, name, v)
        return out

    def run(vals: dict[str, float]) -> Prediction:
        evaluator.plant_params = build(vals)
        evaluator._base_cache.clear()
        return evaluator.predict(views, active)

    def judge(pred: Prediction, spec: ParamSpec) -> float:
        c = pred.channel_cost
        return float(c.sum() if spec.knob is None else c[spec.knob] + c[2 + spec.knob])

    best = run(value)
    evals = 1
    groups = _groups(specs)
    first = coarse_first
    while True:
        for group in groups:
            fractions = np.linspace(0.0, 1.0, 5) if first else np.array([0.25, 0.75])
            if evals + len(fractions) + 1 > max_evals:
                break
            trials = []
            xs: dict[str, list[float]] = {sp.name: [] for sp in group}
            for f in fractions:
                vals = dict(value)
                for sp in group:
                    x = lo[sp.name] + f * (hi[sp.name] - lo[sp.name])
                    xs[sp.name].append(x)
                    place(vals, sp, x)
                trials.append(run(vals))
                evals += 1
            before = dict(value)
            chosen: dict[str, tuple[float, float]] = {}
            for sp in group:
                x = list(xs[sp.name])
                scores = [judge(p, sp) for p in trials]
                if not first:  # the centre is the current value, already judged
                    x.insert(1, centre(sp))
                    scores.insert(1, judge(best, sp))
                xa, ya = np.array(x), np.array(scores)
                k = int(np.argmin(ya))
                new_x = _vertex(xa, ya, k)
                chosen[sp.name] = (float(xa[k]), float(ya[k]))
                # halve the interval around the new value; at an edge keep its width (walk on)
                half = 0.5 * (hi[sp.name] - lo[sp.name])
                at_edge = (k == 0 and xa[k] > sp.lower) or (k == len(xa) - 1 and xa[k] < sp.upper)
                half = half if at_edge and not first else 0.5 * half
                place(value, sp, new_x)
                c = centre(sp)
                lo[sp.name] = max(sp.lower, c - half)
                hi[sp.name] = min(sp.upper, c + half)
            best = run(value)
            evals += 1
            reverted = False
            for sp in group:
                if judge(best, sp) > chosen[sp.name][1]:  # the vertex lost: take the best point
                    x_best = chosen[sp.name][0]
                    if sp.name in plain:
                        value[sp.name] = x_best
                    else:
                        for path in sp.name.split("+"):
                            ps = plain[path]
                            value[path] = float(np.clip(before[path] + x_best, ps.lower,
                                                        ps.upper))
                    reverted = True
            if reverted and evals < max_evals:
                best = run(value)
                evals += 1
        else:
            first = False
            continue
        break
    evaluator.plant_params = build(value)
    evaluator._base_cache.clear()
    return evaluator.plant_params, best.cost


def _nelder_mead(x0: NDArray[np.float64], step: float,
                 ) -> Generator[NDArray[np.float64], float, None]:
    """Nelder-Mead on the unit cube as an ask/tell generator (send the cost of each point).

    A generator, so the two knobs' searches can share one plant run per evaluation.
    """
    d = len(x0)
    pts = [np.clip(x0, 0, 1)]
    for i in range(d):
        e = np.zeros(d)
        e[i] = step if x0[i] + step <= 1 else -step
        pts.append(np.clip(x0 + e, 0, 1))
    vals = []
    for p in pts:
        vals.append((yield p))
    while True:
        order = np.argsort(vals)
        pts = [pts[i] for i in order]
        vals = [vals[i] for i in order]
        c = np.mean(pts[:-1], axis=0)
        xr = np.clip(2 * c - pts[-1], 0, 1)
        fr = yield xr
        if fr < vals[0]:
            xe = np.clip(3 * c - 2 * pts[-1], 0, 1)
            fe = yield xe
            pts[-1], vals[-1] = (xe, fe) if fe < fr else (xr, fr)
        elif fr < vals[-2]:
            pts[-1], vals[-1] = xr, fr
        else:
            xc = np.clip(0.5 * (c + pts[-1]), 0, 1)
            fc = yield xc
            if fc < vals[-1]:
                pts[-1], vals[-1] = xc, fc
            else:
                for i in range(1, d + 1):
                    pts[i] = 0.5 * (pts[0] + pts[i])
                    vals[i] = yield pts[i]


def polish_base(evaluator: Evaluator, views: Sequence[View], specs: Sequence[ParamSpec],
                max_evals: int, active: Active = (), step: float = 0.04) -> tuple[dict[str, Any],
                                                                                  float]:
    """Nelder-Mead polish of the plain base parameters, one search per knob in lockstep.

    Coordinate search stalls in valleys (slack against friction against the tip gain); the
    simplex follows them. Each plant run evaluates both knobs' next points; each search gets
    its knob's cost. Keeps the best point seen per knob.
    """
    params = copy.deepcopy(evaluator.plant_params)
    plain = [s for s in specs if "+" not in s.name]
    groups = {k: [s for s in plain if s.knob == k] for k in (0, 1, None)}
    groups = {k: g for k, g in groups.items() if g}
    if not groups or max_evals < 2:
        return params, evaluator.predict(views, active).cost

    def unit(s: ParamSpec) -> float:
        v = get_param(params, s.name)
        return float(np.clip(((v if v is not None else s.lower) - s.lower)
                             / (s.upper - s.lower), 0, 1))

    def judge(pred: Prediction, k: int | None) -> float:
        c = pred.channel_cost
        return float(c.sum() if k is None else c[k] + c[2 + k])

    gens = {k: _nelder_mead(np.array([unit(s) for s in g]), step) for k, g in groups.items()}
    asks = {k: next(gen) for k, gen in gens.items()}
    best = {k: (np.inf, asks[k]) for k in groups}
    total = np.inf
    for _ in range(max_evals):
        trial = params
        for k, g in groups.items():
            for s, u in zip(g, asks[k], strict=True):
                trial = set_param(trial, s.name, s.lower + float(u) * (s.upper - s.lower))
        evaluator.plant_params = trial
        evaluator._base_cache.clear()
        pred = evaluator.predict(views, active)
        for k in groups:
            f = judge(pred, k)
            if f < best[k][0]:
                best[k] = (f, asks[k].copy())
            asks[k] = gens[k].send(f)
    out = params
    for k, g in groups.items():
        for s, u in zip(g, best[k][1], strict=True):
            out = set_param(out, s.name, s.lower + float(u) * (s.upper - s.lower))
    evaluator.plant_params = out
    evaluator._base_cache.clear()
    total = evaluator.predict(views, active).cost
    return out, total


def fit_candidate(evaluator: Evaluator, views: Sequence[View], cand: Candidate,
                  fixed: Active = (), max_evals: int = 12,
                  start: NDArray[np.float64] | None = None) -> tuple[NDArray[np.float64], float]:
    """Fit one candidate's nonlinear parameters on training rows (plant parameters fixed)."""
    if not cand.param_names:
        theta = np.zeros(0)
        return theta, evaluator.predict(views, [*fixed, (cand, theta)]).cost
    lower = np.array(cand.lower, dtype=float)
    upper = np.array(cand.upper, dtype=float)

    def cost(x: NDArray[np.float64]) -> float:
        return evaluator.predict(views, [*fixed, (cand, x)]).cost

    x0 = np.array(cand.neutral if start is None else start, dtype=float)
    return _search(cost, lower, upper, x0, max_evals)


def joint_refine(evaluator: Evaluator, views: Sequence[View], specs: Sequence[ParamSpec],
                 cand: Candidate | None, theta: NDArray[np.float64], base_params: dict[str, Any],
                 base_evals: int, cand_evals: int) -> tuple[dict[str, Any], NDArray[np.float64],
                                                            float]:
    """Refit the base parameters (narrow interval) with ``cand`` in the model, then ``cand``.

    With ``cand=None`` this is the control: the same extra base fitting without any candidate,
    so a candidate is credited only with what more base fitting alone would not give.
    """
    evaluator.plant_params = copy.deepcopy(base_params)
    evaluator._base_cache.clear()
    active: Active = [] if cand is None else [(cand, theta)]
    params, cost = fit_base(evaluator, views, specs, base_evals, active, width=0.1,
                            coarse_first=False)
    if cand is not None and cand.param_names:
        theta, cost = fit_candidate(evaluator, views, cand, max_evals=cand_evals, start=theta)
    return params, theta, cost
