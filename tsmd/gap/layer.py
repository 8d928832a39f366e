"""The structural layer: a flexible hysteresis model of each knob around the simulator.

A real catheter is never the simulator plus one effect: its base physics differ too. So the
physics simulator's output is wrapped in a layer fitted on training rows by linear least
squares: per knob and channel a generalized Prandtl-Ishlinskii model of the knob (play operators
of several widths with a quadratic envelope, their friction states, load-scaled, dead zones
before and after the plays, a start transient) plus a static polynomial of the simulated tip and
torque, plus one offset per recording. It can take most rate-independent, time-invariant
hysteresis of one knob, so a different dead zone, loop shape or friction law is absorbed and
reported as the *base mismatch*; what it cannot take is what `tsmd.gap.signature` looks for.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.model import View
from tsmd.gap.simulate import lowpass
from tsmd.gap.stats import bootstrap_ratio_ci

PLAY_WIDTHS_DEG: tuple[float, ...] = (0.3, 1.0, 3.0, 8.0, 20.0, 45.0)
"""Play operator half-widths of the structural layer: a dead zone of a few degrees up to a loop
as wide as half the knob range."""

DEAD_ZONES_DEG: tuple[float, ...] = (8.0, 16.0, 24.0, 32.0)
"""Dead zones applied to the play outputs in the tip layer (slack of 10 to 40 deg of knob)."""

START_TRAVEL_DEG: tuple[float, ...] = (100.0, 400.0)
"""Knob travel over which the start transient of the structural layer decays."""

FloatArray = NDArray[np.float64]


@dataclass
class SigData:
    """All recordings' rows on the signature grid, stacked, with per-row bookkeeping."""

    t_run: FloatArray  # time since the recording's start (s)
    frac_run: FloatArray  # the same as a fraction of the recording
    t_s: FloatArray
    knob: FloatArray  # (n, 2)
    vel: FloatArray  # (n, 2)
    sim_tip: FloatArray  # (n, 2)
    sim_torque: FloatArray  # (n, 2)
    measured: FloatArray  # (n, 4)
    valid: NDArray[np.bool_]  # (n, 4)
    train: NDArray[np.bool_]
    test: NDArray[np.bool_]
    rec: NDArray[np.int64]  # recording index
    block: NDArray[np.int64]  # global held-out block id, -1 for training rows
    config: NDArray[np.int64]  # configuration index (0 = the first label seen)
    n_configs: int
    segments: list[slice]  # rows of each recording

    def __len__(self) -> int:
        return len(self.t_s)


def stack_views(views: Sequence[View], configs: Sequence[str]) -> SigData:
    """Stack the signature views (base simulation already run) into one :class:`SigData`."""
    labels = list(dict.fromkeys(configs))
    parts: dict[str, list[FloatArray]] = {k: [] for k in (
        "t_run", "frac", "t", "knob", "vel", "tip", "torque", "meas")}
    valid, train, test, rec, block, conf, segs = [], [], [], [], [], [], []
    start, block_base = 0, 0
    for i, (v, cfg) in enumerate(zip(views, configs, strict=True)):
        assert v.base_tip is not None and v.base_torque is not None
        n = len(v.rows)
        t_run = v.t_s - v.series.t_s[0]
        parts["t_run"].append(t_run)
        parts["frac"].append(t_run / max(v.series.duration_s, 1e-9))
        parts["t"].append(v.t_s)
        parts["knob"].append(v.knob_deg)
        parts["vel"].append(v.vel_deg_s)
        parts["tip"].append(v.base_tip)
        parts["torque"].append(v.base_torque)
        parts["meas"].append(v.measured)
        valid.append(np.broadcast_to(v.valid, (n, 4)))
        train.append(v.train)
        test.append(v.test)
        rec.append(np.full(n, i))
        blk = np.where(v.test, v.block + block_base, -1)
        block.append(blk)
        block_base += int(v.block.max()) + 1 if n else 0
        conf.append(np.full(n, labels.index(cfg)))
        segs.append(slice(start, start + n))
        start += n
    return SigData(
        np.concatenate(parts["t_run"]), np.concatenate(parts["frac"]), np.concatenate(parts["t"]),
        np.vstack(parts["knob"]), np.vstack(parts["vel"]), np.vstack(parts["tip"]),
        np.vstack(parts["torque"]), np.vstack(parts["meas"]), np.vstack(valid),
        np.concatenate(train), np.concatenate(test), np.concatenate(rec),
        np.concatenate(block), np.concatenate(conf), len(labels), segs)


def play_bank(x: FloatArray, widths: Sequence[float]) -> FloatArray:
    """Play (backlash) operators of several half-widths on one signal, (n, len(widths))."""
    w = np.asarray(widths, dtype=float)
    out = np.empty((len(x), len(w)))
    if not len(x):
        return out
    y = np.full(len(w), float(x[0]))
    for k, xk in enumerate(np.asarray(x, dtype=float).tolist()):
        y = np.minimum(np.maximum(y, xk - w), xk + w)
        out[k] = y
    return out


def per_recording(d: SigData, fn: Callable[[slice], FloatArray]) -> FloatArray:
    return np.concatenate([fn(s) for s in d.segments])


@dataclass
class Carriers:
    """Per knob the rows' hysteresis state: what an effect's condition multiplies."""

    layer: list[FloatArray]  # per knob (tip, current) structural-layer columns
    layer_cur: list[FloatArray]
    direction: FloatArray  # (n, 2) smoothed sign of the knob's motion
    sweep_speed: FloatArray  # (n, 2) |v| low-passed over 1 s / 90th percentile
    sens: FloatArray | None = None  # (n, 4) slope of the layer's prediction against the knob
    load: FloatArray | None = None  # (n, 2) signed simulated torque / its 95th percentile


def carriers(d: SigData) -> Carriers:
    """Structural-layer columns and the carriers of every signature, per knob."""
    n = len(d)
    layer, layer_cur = [], []
    direction = np.zeros((n, 2))
    speed = np.zeros((n, 2))
    for j in range(2):
        x = d.knob[:, j]
        v = d.vel[:, j]
        v90 = max(float(np.percentile(np.abs(v), 90)), 1e-6)
        plays = np.vstack([play_bank(x[seg], PLAY_WIDTHS_DEG) for seg in d.segments])
        states = (x[:, None] - plays) / np.asarray(PLAY_WIDTHS_DEG)
        # the direction of motion as the narrowest play's state: it flips after 2 x 0.3 deg of
        # travel at any speed (a velocity sign smoothed in time flips later when fast, which
        # would read as a rate effect)
        direction[:, j] = states[:, 0]
        load = np.abs(x)[:, None] / 90.0
        p = plays / 90.0
        s_scale = max(float(np.percentile(np.abs(d.sim_tip[:, j]), 95)), 1e-6)
        s = d.sim_tip[:, j] / s_scale
        tq_scale = max(float(np.percentile(np.abs(d.sim_torque[:, j]), 95)), 1e-12)
        tq = d.sim_torque[:, j] / tq_scale
        # the start from a straight, unloaded catheter is a state no later motion returns to:
        # a transient over the first sweeps (decaying with the knob travel since the start)
        travel = np.concatenate([np.concatenate([[0.0], np.cumsum(np.abs(np.diff(x[seg])))])
                                 for seg in d.segments])
        start = [np.exp(-travel / w) for w in START_TRAVEL_DEG]
        common = [x / 90.0, (x / 90.0) ** 3, p, p * np.abs(p), states, states * load, *start,
                  *(st * x / 90.0 for st in start)]
        # a dead zone after the friction: the slack of a real catheter need not be the model's
        dead = [np.sign(p) * np.maximum(np.abs(p) - dz / 90.0, 0.0) for dz in DEAD_ZONES_DEG]
        # ... and before it (slack first, then the sheath's friction): plays of the dead-zoned knob
        for dz in DEAD_ZONES_DEG:
            xd = np.sign(x) * np.maximum(np.abs(x) - dz, 0.0)
            dead.append(np.vstack([play_bank(xd[seg], PLAY_WIDTHS_DEG[1:5])
                                   for seg in d.segments]) / 90.0)
        layer.append(np.column_stack([s, s * np.abs(s), s**3, *common, *dead]))
        layer_cur.append(np.column_stack([tq, tq * np.abs(tq), v / v90, s, *common]))
        speed[:, j] = np.concatenate([lowpass(d.t_s[seg], np.abs(v[seg]), 1.0)
                                      for seg in d.segments]) / v90
    return Carriers(layer, layer_cur, direction, speed)


def sensitivity(d: SigData, pred: FloatArray, x: FloatArray,
                window_deg: float = 1.0) -> FloatArray:
    """Slope of a prediction against the knob along the motion (0 where the knob rests).

    Differences over the last ``window_deg`` of knob travel, so a slowly moving knob and a fast
    one give the same slope; the loaded branch has the tip/knob gain, the dead zone about 0.
    """
    out = np.zeros(len(x))
    for seg in d.segments:
        xs, ps = x[seg], pred[seg]
        travel = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(xs)))])
        back = np.clip(np.searchsorted(travel, travel - window_deg, side="right") - 1, 0, None)
        dx = xs - xs[back]
        ok = np.abs(dx) >= 0.5 * window_deg
        slope = np.zeros(len(xs))
        slope[ok] = (ps[ok] - ps[back[ok]]) / dx[ok]
        out[seg] = slope
    return out


RIDGE = 1e-6
"""Ridge of the layer's fits, relative to the mean diagonal of the normal equations: nothing for
well-posed fits, but a held-out recording whose motion leaves the training range (another
acquisition held out whole) is not extrapolated along near-singular directions."""


def _ridge_pinv(a: FloatArray) -> FloatArray:
    """(A'A + r I)^-1 A' with r = RIDGE x mean diagonal of A'A."""
    g = a.T @ a
    r = RIDGE * float(np.trace(g)) / max(g.shape[0], 1) + 1e-12  # all-zero columns: 0
    return np.asarray(np.linalg.solve(g + r * np.eye(g.shape[0]), a.T))


class Layer:
    """The structural layer per channel, fitted on training rows; signatures are added to it.

    Adding a signature's regressors E refits layer + E jointly, done cheaply by projection
    (Frisch-Waugh): E minus its own layer fit, regressed on the layer's training residual. The
    layer's pseudo-inverse is computed once per channel, so a signature and its many
    surrogates cost a few narrow products each.
    """

    def __init__(self, d: SigData, columns: Sequence[FloatArray]) -> None:
        self.d = d
        rec_cols = np.column_stack([(d.rec == i).astype(float) for i in range(len(d.segments))])
        self.design: list[FloatArray] = []
        self.scale: list[FloatArray] = []
        self.pinv: list[FloatArray] = []
        self.rows: list[NDArray[np.bool_]] = []
        self.pred = np.zeros((len(d), 4))
        for ch, cols in enumerate(columns):
            a = np.column_stack([cols, rec_cols])
            scale = np.maximum(np.abs(a).max(axis=0), 1e-12)
            a = a / scale
            rows = d.train & d.valid[:, ch]
            pinv = _ridge_pinv(a[rows]) if rows.any() else np.zeros((a.shape[1], 0))
            self.design.append(a)
            self.pinv.append(pinv)
            self.rows.append(rows)
            if rows.any():
                self.pred[:, ch] = a @ (pinv @ d.measured[rows, ch])

    def add(self, ch: int, extra: FloatArray) -> FloatArray:
        """Prediction of channel ``ch`` by the layer and ``extra`` fitted jointly."""
        rows = self.rows[ch]
        if not rows.any():
            return self.pred[:, ch].copy()
        e = extra / np.maximum(np.abs(extra).max(axis=0), 1e-12)
        e_perp = e - self.design[ch] @ (self.pinv[ch] @ e[rows])
        resid = self.d.measured[rows, ch] - self.pred[rows, ch]
        coef = _ridge_pinv(e_perp[rows]) @ resid
        return np.asarray(self.pred[:, ch] + e_perp @ coef)


def block_costs(d: SigData, pred: FloatArray, noise_var: FloatArray,
                blocks: NDArray[np.int64]) -> tuple[FloatArray, FloatArray]:
    """Per held-out block and channel the noise-weighted squared residual and the number of
    values, both (n_blocks, 4)."""
    r = (pred - d.measured) * d.valid
    w = r * r / noise_var
    idx = np.searchsorted(blocks, d.block[d.test])
    cost = np.column_stack([np.bincount(idx, weights=w[d.test, c], minlength=len(blocks))
                            for c in range(4)]).astype(float)
    count = np.column_stack([np.bincount(idx, weights=d.valid[d.test, c].astype(float),
                                         minlength=len(blocks)) for c in range(4)])
    return cost, count.astype(float)


def channel_weights(base_cost: FloatArray, count: FloatArray) -> FloatArray:
    """Per channel 1 / its held-out excess: every measured channel's gap counts the same.

    In noise units a tip tracked to 0.1 deg outweighs a current measured to 4 mA a hundred
    times, and an effect only in the current (sensor dynamics) would never show. A channel at
    the noise counts as if its excess were half its noise level.
    """
    exc = (base_cost - count).sum(axis=0)
    n = count.sum(axis=0)
    return np.where(n > 0, 1.0 / np.maximum(exc, 0.5 * np.maximum(n, 1.0)), 0.0)


def heldout_metrics(d: SigData, pred: FloatArray, seed: int = 0, n_boot: int = 1000,
                    level: float = 0.9) -> dict[str, float]:
    """Held-out RMSE (with a block-bootstrap interval) and PTPE per channel on the grid."""
    out: dict[str, float] = {}
    blocks = np.unique(d.block[d.test])
    for ch, (name, unit) in enumerate((("tip1", "deg"), ("tip2", "deg"), ("cur1", "A"),
                                       ("cur2", "A"))):
        rows = d.test & d.valid[:, ch]
        if not rows.any():
            for key in ("rmse", "rmse_lo", "rmse_hi"):
                out[f"{name}_{key}_{unit}"] = float("nan")
            if ch < 2:
                out[f"{name}_ptpe_{unit}"] = float("nan")
            continue
        r = pred[rows, ch] - d.measured[rows, ch]
        idx = np.searchsorted(blocks, d.block[rows])
        ss = np.bincount(idx, weights=r * r, minlength=len(blocks)).astype(float)
        n = np.bincount(idx, minlength=len(blocks)).astype(float)
        keep = n > 0
        point, lo, hi = bootstrap_ratio_ci(ss[keep], n[keep], seed, n_boot, level)
        out[f"{name}_rmse_{unit}"] = float(np.sqrt(point))
        out[f"{name}_rmse_lo_{unit}"] = float(np.sqrt(lo)) if np.isfinite(lo) else float("nan")
        out[f"{name}_rmse_hi_{unit}"] = float(np.sqrt(hi)) if np.isfinite(hi) else float("nan")
        if ch < 2:
            out[f"{name}_ptpe_{unit}"] = float(r.max() - r.min())
    return out
