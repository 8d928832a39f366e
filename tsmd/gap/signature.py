"""Effect signatures on top of a flexible hysteresis layer: a diagnosis that survives wrong physics.

A real catheter is never the simulator plus one effect: its base physics differ too. So the
physics simulator's output is wrapped in a *structural layer*, fitted on training rows by linear
least squares: per knob and channel, a generalized Prandtl-Ishlinskii model of the knob (play
operators of several widths with a quadratic envelope, their friction states, load-scaled) plus
a static polynomial of the simulated tip and torque, plus one offset per recording. It can take
any rate-independent, time-invariant hysteresis of one knob, so a different dead zone, loop shape
or friction law is absorbed and is reported as the *base mismatch*.

What such a layer cannot take is what an unmodelled effect adds: dependence on a condition the
layer does not see. Each effect has its condition (the other knob's angle: coupling; the sweep
speed: rate; the load at the last reversal and the travel since: compliance; time in the run:
drift and creep; the current's timing against the knob: sensor dynamics; the recording's sheath
configuration: curvature). Its signature is a small set of condition x carrier regressors. A
signature's held-out gain is compared with the gain of the same regressors built from a
*surrogate* condition taken from the data themselves (circularly shifted within each recording,
configurations re-drawn over time blocks, a lead instead of a lag): generic flexibility that
mops up any structured residual gains as much with the surrogate, a real effect does not. The
per-block difference is bootstrapped over held-out blocks.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.model import View
from tsmd.gap.simulate import lowpass
from tsmd.gap.stats import bootstrap_ratio_ci

PLAY_WIDTHS_DEG: tuple[float, ...] = (1.0, 3.0, 8.0, 20.0, 45.0)
"""Play operator half-widths of the structural layer: a dead zone of a few degrees up to a loop
as wide as half the knob range."""

DEAD_ZONES_DEG: tuple[float, ...] = (8.0, 16.0, 24.0, 32.0)
"""Dead zones applied to the play outputs in the tip layer (slack of 10 to 40 deg of knob)."""

SIGNATURES: dict[str, tuple[str, str]] = {
    "coupling": ("coupling between the knobs", "the other knob's angle"),
    "rate": ("rate dependence", "the sweep speed"),
    "compliance": ("tendon compliance", "the load at the last reversal and the travel since"),
    "drift": ("drift / creep", "time in the run"),
    "sensor": ("current-sensor dynamics", "the current's lag against the knob"),
    "curvature": ("sheath curvature / shape", "the recording's sheath configuration"),
}
"""Signature name -> (effect, the condition it depends on)."""

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


def _per_recording(d: SigData, fn: Callable[[slice], FloatArray]) -> FloatArray:
    return np.concatenate([fn(s) for s in d.segments])


@dataclass
class Carriers:
    """Per knob the rows' hysteresis state: what an effect's condition multiplies."""

    layer: list[FloatArray]  # per knob (tip, current) structural-layer columns
    layer_cur: list[FloatArray]
    direction: FloatArray  # (n, 2) smoothed sign of the knob's motion
    bend: FloatArray  # (n, 2) simulated tip / its 95th percentile
    loaded: FloatArray  # (n, 2) 1 where the simulated tip follows the knob
    sweep_speed: FloatArray  # (n, 2) |v| low-passed over 1 s / 90th percentile
    load_at_rev: FloatArray  # (n, 2) |bend| at the last reversal
    travel_since: FloatArray  # (n, 2) knob travel since the last reversal (deg)


def carriers(d: SigData) -> Carriers:
    """Structural-layer columns and the carriers of every signature, per knob."""
    n = len(d)
    layer, layer_cur = [], []
    direction = np.zeros((n, 2))
    bend = np.zeros((n, 2))
    loaded = np.zeros((n, 2))
    speed = np.zeros((n, 2))
    load_rev = np.zeros((n, 2))
    since = np.zeros((n, 2))
    for j in range(2):
        x = d.knob[:, j]
        v = d.vel[:, j]
        v90 = max(float(np.percentile(np.abs(v), 90)), 1e-6)
        direction[:, j] = np.tanh(v / (0.05 * v90))
        plays = np.vstack([play_bank(x[seg], PLAY_WIDTHS_DEG) for seg in d.segments])
        states = (x[:, None] - plays) / np.asarray(PLAY_WIDTHS_DEG)
        load = np.abs(x)[:, None] / 90.0
        p = plays / 90.0
        s_scale = max(float(np.percentile(np.abs(d.sim_tip[:, j]), 95)), 1e-6)
        s = d.sim_tip[:, j] / s_scale
        tq_scale = max(float(np.percentile(np.abs(d.sim_torque[:, j]), 95)), 1e-12)
        tq = d.sim_torque[:, j] / tq_scale
        common = [x / 90.0, (x / 90.0) ** 3, p, p * np.abs(p), states, states * load]
        # a dead zone after the friction: the slack of a real catheter need not be the model's
        dead = [np.sign(p) * np.maximum(np.abs(p) - dz / 90.0, 0.0) for dz in DEAD_ZONES_DEG]
        layer.append(np.column_stack([s, s * np.abs(s), s**3, *common, *dead]))
        layer_cur.append(np.column_stack([tq, tq * np.abs(tq), direction[:, j], v / v90,
                                          s, *common]))
        bend[:, j] = s
        slope = np.abs(np.gradient(d.sim_tip[:, j])) / np.maximum(np.abs(np.gradient(x)), 1e-9)
        loaded[:, j] = (slope > 0.3 * max(float(np.percentile(slope, 90)), 1e-9)).astype(float)
        speed[:, j] = np.concatenate([lowpass(d.t_s[seg], np.abs(v[seg]), 1.0)
                                      for seg in d.segments]) / v90
        lr, ts = _per_recording_rev(d, x, np.abs(s))
        load_rev[:, j], since[:, j] = lr, ts
    return Carriers(layer, layer_cur, direction, bend, loaded, speed, load_rev, since)


def _per_recording_rev(d: SigData, x: FloatArray,
                       load: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Per row: ``load`` at the last reversal of ``x`` (>= 1 deg back) and the travel since."""
    at_rev = np.zeros(len(x))
    since = np.zeros(len(x))
    for seg in d.segments:
        xs = x[seg].tolist()
        ls = load[seg]
        if not xs:
            continue
        ext_i, rising = 0, 0
        lr, rev_x = float(ls[0]), xs[0]
        out_l = np.empty(len(xs))
        out_t = np.empty(len(xs))
        for k, xk in enumerate(xs):
            e = xs[ext_i]
            if (rising >= 0 and xk >= e) or (rising <= 0 and xk <= e):
                if rising == 0 and abs(xk - xs[0]) >= 1.0:
                    rising = 1 if xk > xs[0] else -1
                ext_i = k
            elif rising != 0 and abs(xk - e) >= 1.0:
                lr, rev_x = float(ls[ext_i]), e
                rising = -rising
                ext_i = k
            out_l[k] = lr
            out_t[k] = abs(xk - rev_x)
        at_rev[seg], since[seg] = out_l, out_t
    return at_rev, since


def _shift(d: SigData, a: FloatArray, rng: np.random.Generator) -> FloatArray:
    """``a`` circularly shifted within each recording by 20..80 % of its length (a surrogate)."""
    out = a.copy()
    for seg in d.segments:
        n = seg.stop - seg.start
        if n > 4:
            out[seg] = np.roll(a[seg], int(rng.integers(n // 5, max(4 * n // 5, n // 5 + 1))),
                               axis=0)
    return out


def signature_columns(name: str, d: SigData, c: Carriers, j: int, channel: str,
                      cond: FloatArray) -> FloatArray | None:
    """Regressors of signature ``name`` for knob ``j``'s ``channel`` ('tip' or 'cur').

    ``cond`` is the signature's condition (true or surrogate); the carriers are the row's own
    hysteresis state, so an effect that acts only while loaded or in one direction fits.
    """
    dirn, bend, loaded = c.direction[:, j], c.bend[:, j], c.loaded[:, j]
    if name == "coupling":
        o = cond[:, 1 - j] / 90.0
        cols = [f * g for f in (o, o * o) for g in (np.ones(len(o)), dirn, bend, loaded * dirn)]
    elif name == "rate":
        sp = cond[:, j]
        cols = [sp, sp * dirn, sp * bend, sp * loaded * dirn, sp * dirn * np.abs(bend)]
        if channel == "cur":
            tq = d.sim_torque[:, j] / max(float(np.percentile(np.abs(d.sim_torque[:, j]), 95)),
                                          1e-12)
            cols += [sp * tq, sp * tq * dirn]
    elif name == "compliance":
        lr, tr = cond[:, j], c.travel_since[:, j]
        cols = [lr * dirn * (1.0 - np.exp(-tr / w)) for w in (2.0, 8.0, 25.0)]
        cols += [lr * dirn, lr * bend]
    elif name == "drift":
        tt = cond[:, 0]
        cols = [tt, tt * bend, tt * dirn, tt * np.maximum(bend, 0), tt * np.minimum(bend, 0)]
    elif name == "curvature":
        if d.n_configs < 2:
            return None
        cols = []
        for k in range(1, d.n_configs):
            z = (cond[:, 0] == k).astype(float)
            cols += [z * dirn, z * bend, z * loaded * dirn, z * bend * np.abs(bend),
                     z * c.layer[j][:, 3], z * c.layer[j][:, 5]]
    else:
        raise ValueError(f"unknown signature {name!r}")
    return np.column_stack(cols)


def _lag_features(d: SigData, pred: FloatArray, lead: bool) -> FloatArray:
    """First-order lag (or, as the surrogate, lead) of a predicted current minus itself."""
    cols = []
    for tau in (0.03, 0.1, 0.3):
        def filt(s: slice, tau: float = tau) -> FloatArray:
            if not lead:
                return lowpass(d.t_s[s], pred[s], tau) - pred[s]
            rev = lowpass(-d.t_s[s][::-1], pred[s][::-1], tau)[::-1]
            return rev - pred[s]
        cols.append(_per_recording(d, filt))
    return np.column_stack(cols)


@dataclass
class SignatureScore:
    """One signature's held-out result against its surrogate null."""

    name: str
    title: str
    condition: str
    share: float
    """Share of the structural layer's held-out excess the signature removes beyond its null."""
    ci: tuple[float, float]
    significant: bool
    raw_share: float
    """Share it removes with the true condition, before subtracting the null."""
    null_share: float
    """Mean share its surrogates remove."""


@dataclass
class SignatureResult:
    """The structural layer's fit and every signature's score, plus held-out figures."""

    scores: list[SignatureScore]
    layer_excess: float
    """Held-out excess of the structural layer (noise units, summed): what effects may explain."""
    physics_excess: float
    """The same for the physics simulator alone (its own linear output map)."""
    layer_ratio: float
    """Held-out residual / noise of the structural layer (1 = noise only)."""
    predictions: dict[str, FloatArray]
    """'physics', 'layer' and each signature's name -> (n, 4) predictions on the grid."""


def _solve(a: FloatArray, b: FloatArray, ridge: float) -> FloatArray:
    scale = np.maximum(np.abs(a).max(axis=0), 1e-12)
    an = a / scale
    if ridge > 0:
        k = an.shape[1]
        an = np.vstack([an, np.sqrt(ridge * len(b)) * np.eye(k)])
        b = np.concatenate([b, np.zeros(k)])
    sol, *_ = np.linalg.lstsq(an, b, rcond=None)
    return np.asarray(sol / scale)


class Layer:
    """Fits a channel's columns on training rows and predicts every row."""

    def __init__(self, d: SigData, ridge: float = 1e-7) -> None:
        self.d = d
        self.ridge = ridge
        self.rec_cols = np.column_stack([(d.rec == i).astype(float)
                                         for i in range(len(d.segments))])

    def fit_predict(self, ch: int, cols: FloatArray) -> FloatArray:
        d = self.d
        a = np.column_stack([cols, self.rec_cols])
        rows = d.train & d.valid[:, ch]
        if not rows.any():
            return np.zeros(len(d))
        coef = _solve(a[rows], d.measured[rows, ch], self.ridge)
        return np.asarray(a @ coef)


def block_costs(d: SigData, pred: FloatArray, noise_var: FloatArray,
                blocks: NDArray[np.int64]) -> tuple[FloatArray, FloatArray]:
    """Per held-out block the noise-weighted squared residual and the number of values."""
    r = (pred - d.measured) * d.valid
    w = np.sum(r * r / noise_var, axis=1)
    idx = np.searchsorted(blocks, d.block[d.test])
    cost = np.bincount(idx, weights=w[d.test], minlength=len(blocks)).astype(float)
    count = np.bincount(idx, weights=d.valid[d.test].sum(axis=1).astype(float),
                        minlength=len(blocks)).astype(float)
    return cost, count


def score_signatures(d: SigData, noise_var: FloatArray, physics_pred: FloatArray,
                     seed: int = 0, n_surrogates: int = 6, n_boot: int = 2000,
                     ci_level: float = 0.9, family_alpha: float = 0.05,
                     min_share: float = 0.05,
                     names: Sequence[str] | None = None) -> SignatureResult:
    """Fit the structural layer, then every signature against its surrogate null."""
    rng = np.random.default_rng(seed)
    c = carriers(d)
    layer = Layer(d)
    blocks = np.unique(d.block[d.test])
    base = np.zeros((len(d), 4))
    for j in range(2):
        base[:, j] = layer.fit_predict(j, c.layer[j])
        base[:, 2 + j] = layer.fit_predict(2 + j, c.layer_cur[j])
    base_cost, count = block_costs(d, base, noise_var, blocks)
    phys_cost, _ = block_costs(d, physics_pred, noise_var, blocks)
    excess = base_cost - count
    total_excess = float(excess.sum())
    conditions: dict[str, Callable[[np.random.Generator | None], FloatArray]] = {
        "coupling": lambda g: d.knob if g is None else _shift(d, d.knob, g),
        "rate": lambda g: c.sweep_speed if g is None else _shift(d, c.sweep_speed, g),
        "compliance": lambda g: (c.load_at_rev if g is None
                                 else _shift(d, c.load_at_rev, g)),
        "drift": lambda g: (d.frac_run[:, None] if g is None
                            else _shift(d, d.frac_run[:, None], g)),
        "curvature": lambda g: (d.config[:, None].astype(float) if g is None
                                else _pseudo_configs(d, g)[:, None]),
    }
    wanted = list(SIGNATURES) if names is None else [n for n in SIGNATURES if n in names]
    preds: dict[str, FloatArray] = {"physics": physics_pred, "layer": base}
    scores = []
    n_tried = sum(1 for n in wanted if n != "curvature" or d.n_configs >= 2)
    for name in wanted:
        if name == "curvature" and d.n_configs < 2:
            continue

        def augmented(cond_for: Callable[[int], FloatArray | None]) -> FloatArray:
            out = base.copy()
            for j in range(2):
                for ch, lay in ((j, c.layer[j]), (2 + j, c.layer_cur[j])):
                    extra = cond_for(ch)
                    if extra is None:
                        continue
                    out[:, ch] = layer.fit_predict(ch, np.column_stack([lay, extra]))
            return out

        def columns(cond: FloatArray, name: str = name) -> Callable[[int], FloatArray | None]:
            return lambda ch: signature_columns(name, d, c, ch % 2, "tip" if ch < 2 else "cur",
                                                cond)

        if name == "sensor":
            true_pred = augmented(lambda ch: None if ch < 2 else _lag_features(
                d, base[:, ch], lead=False))
            null_preds = [augmented(lambda ch: None if ch < 2 else _lag_features(
                d, base[:, ch], lead=True))]
        else:
            cond_fn = conditions[name]
            true_pred = augmented(columns(cond_fn(None)))
            null_preds = [augmented(columns(cond_fn(rng))) for _ in range(n_surrogates)]
        true_cost, _ = block_costs(d, true_pred, noise_var, blocks)
        null_cost = np.mean([block_costs(d, p, noise_var, blocks)[0] for p in null_preds],
                            axis=0)
        gain = null_cost - true_cost  # what the true condition removes beyond its surrogates
        denom = np.maximum(excess, 0.0) if total_excess > 0 else count
        share, lo, hi = bootstrap_ratio_ci(gain, denom, seed, n_boot, ci_level)
        _, strict_lo, _ = bootstrap_ratio_ci(gain, denom, seed, n_boot,
                                             1.0 - 2.0 * family_alpha / max(n_tried, 1))
        raw = float((base_cost - true_cost).sum() / max(float(denom.sum()), 1e-12))
        null = float((base_cost - null_cost).sum() / max(float(denom.sum()), 1e-12))
        title, condition = SIGNATURES[name]
        scores.append(SignatureScore(name, title, condition, share, (lo, hi),
                                     bool(strict_lo > 0 and share >= min_share), raw, null))
        preds[name] = true_pred
    scores.sort(key=lambda s: -s.share)
    return SignatureResult(scores, total_excess, float((phys_cost - count).sum()),
                           float(base_cost.sum() / max(float(count.sum()), 1e-12)), preds)


def _pseudo_configs(d: SigData, rng: np.random.Generator) -> FloatArray:
    """Configuration labels re-drawn over time blocks: same label shares, no link to shape."""
    out = np.zeros(len(d))
    # cut every recording into 8 stretches and shuffle the configuration labels among them
    pieces = []
    for seg in d.segments:
        edges = np.linspace(seg.start, seg.stop, 9).astype(int)
        pieces += [slice(a, b) for a, b in itertools.pairwise(edges)]
    labels = [int(d.config[p.start]) if p.stop > p.start else 0 for p in pieces]
    for p, lab in zip(pieces, rng.permutation(labels), strict=True):
        out[p] = lab
    return out


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
