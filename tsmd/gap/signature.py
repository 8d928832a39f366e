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
from scipy import stats

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
    sens: FloatArray | None = None  # (n, 4) slope of the layer's prediction against the knob
    load: FloatArray | None = None  # (n, 2) signed simulated torque / its 95th percentile


def carriers(d: SigData) -> Carriers:
    """Structural-layer columns and the carriers of every signature, per knob."""
    n = len(d)
    layer, layer_cur = [], []
    direction = np.zeros((n, 2))
    bend = np.zeros((n, 2))
    loaded = np.zeros((n, 2))
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
        bend[:, j] = s
        slope = np.abs(np.gradient(d.sim_tip[:, j])) / np.maximum(np.abs(np.gradient(x)), 1e-9)
        loaded[:, j] = (slope > 0.3 * max(float(np.percentile(slope, 90)), 1e-9)).astype(float)
        speed[:, j] = np.concatenate([lowpass(d.t_s[seg], np.abs(v[seg]), 1.0)
                                      for seg in d.segments]) / v90
    return Carriers(layer, layer_cur, direction, bend, loaded, speed)


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

    Most effects act like a change of the knob angle the tendon sees (a dead zone shifted by
    the other knob, play widened by speed, stretch under load, slack creeping): to first order
    the channel then moves by its sensitivity to the knob (``c.sens``, the slope of the
    structural layer's prediction) times that change. So the regressors are sensitivity x
    condition x the direction or side of the motion, plus a few direct terms.
    """
    assert c.sens is not None and c.load is not None
    ch = j if channel == "tip" else 2 + j
    g = c.sens[:, ch]
    dirn = c.direction[:, j]
    side = np.tanh(d.knob[:, j] / 5.0)
    if name == "coupling":
        o = cond[:, 1 - j] / 90.0
        cols = [g * o, g * o * o * side, g * o * o * dirn]
    elif name == "rate":
        sp = cond[:, j]
        cols = [g * sp * dirn, g * sp * dirn * np.abs(c.load[:, j]), sp * dirn]
        if channel == "cur":
            tq = d.sim_torque[:, j] / max(float(np.percentile(np.abs(d.sim_torque[:, j]), 95)),
                                          1e-12)
            cols += [sp * tq]
    elif name == "compliance":
        ld = cond[:, j]
        cols = [g * ld]  # elastic: lost motion with the tension, whichever way the knob moves
    elif name == "drift":
        tt = cond[:, 0]
        cols = [tt, g * tt * side]
    elif name == "curvature":
        if d.n_configs < 2:
            return None
        cols = []
        for k in range(1, d.n_configs):
            z = (cond[:, 0] == k).astype(float)
            cols += [z * g * dirn, z * g * side, z * dirn, z * g * d.knob[:, j] / 90.0]
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
    z: float = float("nan")
    """How many surrogate standard deviations the true condition's gain lies above theirs."""


@dataclass
class SignatureResult:
    """The structural layer's fit and every signature's score, plus held-out figures."""

    scores: list[SignatureScore]
    layer_excess: float
    """Held-out excess of the structural layer (each channel in units of its own excess, so
    about the number of measured channels): what effects may explain."""
    physics_excess: float
    """The same for the physics simulator alone (its own linear output map)."""
    noise_level: float
    """What the held-out cost would be at the noise alone, in the same units."""
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
            pinv = (np.linalg.pinv(a[rows], rcond=1e-9) if rows.any()
                    else np.zeros((a.shape[1], 0)))
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
        coef, *_ = np.linalg.lstsq(e_perp[rows], resid, rcond=1e-9)
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


def score_signatures(d: SigData, noise_var: FloatArray, physics_pred: FloatArray,
                     seed: int = 0, n_surrogates: int = 30, n_boot: int = 2000,
                     ci_level: float = 0.9, family_alpha: float = 0.05,
                     min_share: float = 0.05,
                     names: Sequence[str] | None = None) -> SignatureResult:
    """Fit the structural layer, then every signature against its surrogate null."""
    rng = np.random.default_rng(seed)
    c = carriers(d)
    layer = Layer(d, [c.layer[0], c.layer[1], c.layer_cur[0], c.layer_cur[1]])
    blocks = np.unique(d.block[d.test])
    base = layer.pred
    c.sens = np.column_stack([sensitivity(d, base[:, ch], d.knob[:, ch % 2])
                              for ch in range(4)])
    c.load = d.sim_torque / np.maximum(np.percentile(np.abs(d.sim_torque), 95, axis=0), 1e-12)
    load = c.load
    base_cost_c, count_c = block_costs(d, base, noise_var, blocks)
    phys_cost_c, _ = block_costs(d, physics_pred, noise_var, blocks)
    weight = channel_weights(base_cost_c, count_c)
    base_cost, count = base_cost_c @ weight, count_c @ weight
    phys_cost = phys_cost_c @ weight
    excess = np.maximum(base_cost_c - count_c, 0.0) @ weight
    total_excess = float(excess.sum())
    conditions: dict[str, Callable[[np.random.Generator | None], FloatArray]] = {
        "coupling": lambda g: d.knob if g is None else _shift(d, d.knob, g),
        "rate": lambda g: c.sweep_speed if g is None else _shift(d, c.sweep_speed, g),
        "compliance": lambda g: load if g is None else _shift(d, load, g),
        "drift": lambda g: (d.frac_run[:, None] if g is None
                            else _slow_wave(d, g)[:, None]),
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

        def augmented(extra: dict[int, FloatArray | None]) -> FloatArray:
            """The layer and the signature's regressors fitted jointly on training rows."""
            out = base.copy()
            for ch, cols in extra.items():
                if cols is not None:
                    out[:, ch] = layer.add(ch, cols)
            return out

        def columns(cond: FloatArray, name: str = name) -> dict[int, FloatArray | None]:
            return {ch: signature_columns(name, d, c, ch % 2, "tip" if ch < 2 else "cur", cond)
                    for ch in range(4)}

        strongest: FloatArray | None = None
        if name == "sensor":
            lag = {ch: _lag_features(d, base[:, ch], lead=False) for ch in (2, 3)}
            true_pred = augmented(dict(lag))
            strongest = augmented({ch: _lag_features(d, base[:, ch], lead=True)
                                   for ch in (2, 3)})
            null_preds = [augmented({ch: _shift(d, lag[ch], rng) for ch in (2, 3)})
                          for _ in range(n_surrogates)]
        else:
            cond_fn = conditions[name]
            true_pred = augmented(columns(cond_fn(None)))
            null_preds = [augmented(columns(cond_fn(rng))) for _ in range(n_surrogates)]
        true_cost = block_costs(d, true_pred, noise_var, blocks)[0] @ weight
        null_costs = np.array([block_costs(d, p, noise_var, blocks)[0] @ weight
                               for p in null_preds])
        null_cost = null_costs.mean(axis=0)
        if strongest is not None:  # a lead is the null a lag must beat
            null_cost = np.minimum(null_cost, block_costs(d, strongest, noise_var,
                                                          blocks)[0] @ weight)
        gain = null_cost - true_cost  # what the true condition removes beyond its surrogates
        denom = np.maximum(excess, 0.0) if total_excess > 0 else count
        share, lo, hi = bootstrap_ratio_ci(gain, denom, seed, n_boot, ci_level)
        _, strict_lo, _ = bootstrap_ratio_ci(gain, denom, seed, n_boot,
                                             1.0 - 2.0 * family_alpha / max(n_tried, 1))
        # the surrogates' spread: is the true condition's gain outside what chance alignment of
        # any condition with this residual gives? (one-sided, Bonferroni over the signatures)
        spread = float(np.std(null_costs.sum(axis=1), ddof=1)) if n_surrogates > 1 else 0.0
        z = float((null_cost.sum() - true_cost.sum()) / max(spread, 1e-12))
        z_crit = float(stats.norm.ppf(1.0 - family_alpha / max(n_tried, 1)))
        raw = float((base_cost - true_cost).sum() / max(float(denom.sum()), 1e-12))
        null = float((base_cost - null_cost).sum() / max(float(denom.sum()), 1e-12))
        title, condition = SIGNATURES[name]
        scores.append(SignatureScore(name, title, condition, share, (lo, hi),
                                     bool(strict_lo > 0 and share >= min_share and z > z_crit),
                                     raw, null, z))
        preds[name] = true_pred
    scores.sort(key=lambda s: -s.share)
    return SignatureResult(scores, float((base_cost - count).sum()),
                           float((phys_cost - count).sum()), float(count.sum()),
                           float(base_cost.sum() / max(float(count.sum()), 1e-12)), preds)


def _slow_wave(d: SigData, rng: np.random.Generator) -> FloatArray:
    """A slow wave over each recording (0.5..1.5 cycles, random phase): the null of a drift.

    A slowly structured residual (a loop shape that changes with the slow cycles of the motion)
    fits a ramp about as well as a wave of the same time scale; a real drift fits the ramp.
    """
    cycles, phase = rng.uniform(0.5, 1.5), rng.uniform(0.0, 2.0 * np.pi)
    return np.sin(2.0 * np.pi * cycles * d.frac_run + phase)


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
