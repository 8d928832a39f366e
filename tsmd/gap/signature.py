"""Effect signatures on top of the structural layer, scored against surrogate nulls.

What the structural layer (:mod:`tsmd.gap.layer`) cannot take is what an unmodelled effect adds:
dependence on a condition the layer does not see. Each effect has its condition (the other
knob's angle: coupling; the sweep speed: rate; the load: compliance; time in the run: drift and
creep; the current's timing against the knob: sensor dynamics; the recording's sheath
configuration: curvature). Its signature is a few condition x carrier regressors, fitted jointly
with the layer on training rows. Its held-out gain is compared with the gain of the same
regressors built from *surrogate* conditions taken from the data themselves (shifted within each
recording, a slow wave for time, configurations re-drawn over stretches, a lead for a lag):
generic flexibility that mops up any structured residual gains as much with a surrogate, a real
effect does not. Significant: above the surrogates' spread (z, Bonferroni over the signatures),
a block-bootstrap lower bound above zero, and at least ``min_share`` of the layer's excess.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

from tsmd.gap.layer import (
    Carriers,
    FloatArray,
    Layer,
    SigData,
    block_costs,
    carriers,
    channel_weights,
    per_recording,
    sensitivity,
)
from tsmd.gap.simulate import lowpass
from tsmd.gap.stats import bootstrap_ratio_ci

SIGNATURES: dict[str, tuple[str, str]] = {
    "coupling": ("coupling between the knobs", "the other knob's angle"),
    "rate": ("rate dependence", "the sweep speed"),
    "compliance": ("tendon compliance", "the tendon load (simulated knob torque)"),
    "drift": ("drift / creep", "time in the run"),
    "sensor": ("current-sensor dynamics", "the current's lag against the knob"),
    "curvature": ("sheath curvature / shape", "the recording's sheath configuration"),
}
"""Signature name -> (effect, the condition it depends on)."""

ACTS_ON: dict[str, tuple[int, ...]] = {"sensor": (2, 3)}
"""Channels (tip1, tip2, cur1, cur2) an effect acts on, when not all: a share is of their excess."""


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
        cols.append(per_recording(d, filt))
    return np.column_stack(cols)


@dataclass
class SignatureScore:
    """One signature's held-out result against its surrogate null."""

    name: str
    title: str
    condition: str
    share: float
    """Share of the structural layer's held-out excess (in the channels the effect acts on)
    that the signature removes beyond its null."""
    ci: tuple[float, float]
    significant: bool
    raw_share: float
    """Share it removes with the true condition, before subtracting the null."""
    null_share: float
    """Mean share its surrogates remove."""
    z: float = float("nan")
    """How many surrogate standard deviations the true condition's gain lies above theirs."""
    size_deg: float = float("nan")
    """A matched loop test's contrast above the repeats' noise (deg; NaN for the others)."""
    within_spread_deg: float = float("nan")
    """A referenced loop test (rate, coupling) not significant whose contrast beyond the
    model's mean unit would be (p, share and size counting the reference's noise only): its
    size there (deg). Such a unit lies inside its model's units' spread, where an effect
    cannot be told from unit scatter (session 17); NaN otherwise."""
    spread_deg: float = float("nan")
    """The model's units' spread that test's contrast is allowed (deg RMS per matched point;
    NaN without a reference of two or more units)."""


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
        # its share is of the excess in the channels it acts on (sensor dynamics: the currents)
        acts = np.zeros(4)
        acts[list(ACTS_ON.get(name, range(4)))] = 1.0
        own = np.maximum(base_cost_c - count_c, 0.0) @ (weight * acts)
        denom = own if total_excess > 0 and float(own.sum()) > 0 else count
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


