"""Where the gap lies: residuals broken down by regime, direction, the other knob, speed, time.

Every row of one knob's channels (its tip angle and its current) gets a label per factor. The
share a factor "holds" is the fraction of the residual sum of squares removed by subtracting the
mean residual of each of its bins: the part of the gap that is a systematic offset tied to it.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FACTORS: tuple[str, ...] = ("regime", "direction", "other_knob", "speed", "since_reversal",
                            "time_in_run")


def reversals(knob_deg: NDArray[np.float64], threshold_deg: float) -> NDArray[np.bool_]:
    """Rows where the knob turned back by more than ``threshold_deg`` from its last extreme.

    The flag is set at the extreme itself. Direction is +1/-1 between reversals.
    """
    n = len(knob_deg)
    flags = np.zeros(n, dtype=bool)
    if n == 0:
        return flags
    direction = 0
    extreme_i = 0
    for k in range(1, n):
        x = knob_deg[k]
        ext = knob_deg[extreme_i]
        if direction == 0:
            if abs(x - ext) >= threshold_deg:
                direction = 1 if x > ext else -1
                extreme_i = k
            continue
        if (direction > 0 and x >= ext) or (direction < 0 and x <= ext):
            extreme_i = k
            continue
        if abs(x - ext) >= threshold_deg:
            flags[extreme_i] = True
            direction = -direction
            extreme_i = k
    return flags


def flat_mask(knob_deg: NDArray[np.float64], tip_sim: NDArray[np.float64],
              window_deg: float = 2.0) -> NDArray[np.bool_]:
    """Rows where the simulated tip barely moves with the knob (slope < 30 % of loaded slope)."""
    travel = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(knob_deg)))])
    j = np.searchsorted(travel, travel - window_deg, side="right") - 1
    j = np.clip(j, 0, len(travel) - 1)
    du = travel - travel[j]
    moving = du >= 0.5 * window_deg
    slope = np.zeros(len(knob_deg))
    slope[moving] = np.abs(tip_sim[moving] - tip_sim[j[moving]]) / du[moving]
    ref = float(np.percentile(slope[moving], 90)) if moving.any() else 0.0
    flat = slope < 0.3 * ref
    # still rows inherit the last moving row's state
    last = np.maximum.accumulate(np.where(moving, np.arange(len(flat)), 0))
    return flat[last]


@dataclass(frozen=True)
class KnobLabels:
    """Per-row labels of one knob's channels, one string array per factor."""

    labels: dict[str, NDArray[np.str_]]


def label_knob(t_s: NDArray[np.float64], knob_deg: NDArray[np.float64],
               other_deg: NDArray[np.float64], vel_deg_s: NDArray[np.float64],
               tip_sim: NDArray[np.float64], t_run_s: NDArray[np.float64],
               run_s: float, speed_edges: NDArray[np.float64]) -> KnobLabels:
    """Labels for one knob of one series (all rows of the full-rate or eval grid)."""
    span = float(np.ptp(knob_deg))
    rev = reversals(knob_deg, max(0.5, 0.01 * span))
    window_deg = max(2.0, 0.02 * span)
    flat = flat_mask(knob_deg, tip_sim, window_deg)
    n = len(knob_deg)
    regime = np.empty(n, dtype=object)
    since = np.full(n, np.inf)
    last_rev_t = -np.inf
    loaded_since_rev = True
    rev_knob = knob_deg[0]
    for k in range(n):
        if rev[k]:
            last_rev_t = t_s[k]
            rev_knob = knob_deg[k]
            loaded_since_rev = False
        since[k] = t_s[k] - last_rev_t
        if not loaded_since_rev and abs(knob_deg[k] - rev_knob) < window_deg:
            regime[k] = "after reversal"  # the slope window still reaches back past the turn
        elif not flat[k]:
            loaded_since_rev = True
            regime[k] = "loaded"
        elif not loaded_since_rev:
            regime[k] = "after reversal"
        else:
            regime[k] = "dead zone"
    still = np.abs(vel_deg_s) < 0.02 * max(float(np.percentile(np.abs(vel_deg_s), 95)), 1e-9)
    direction = np.where(still, "still", np.where(vel_deg_s > 0, "+", "-"))
    other_edges = [-np.inf, -45.0, -15.0, 15.0, 45.0, np.inf]
    other_names = ["<-45", "-45..-15", "-15..15", "15..45", ">45"]
    other = np.array(other_names, dtype=object)[np.digitize(other_deg, other_edges[1:-1])]
    speed_names = [f"{a:.3g}..{b:.3g} deg/s" for a, b in itertools.pairwise(speed_edges)]
    speed = np.array(speed_names, dtype=object)[
        np.clip(np.digitize(np.abs(vel_deg_s), speed_edges[1:-1]), 0, len(speed_names) - 1)]
    since_edges = [1.0, 3.0, 10.0]
    since_names = ["<1 s", "1-3 s", "3-10 s", ">10 s"]
    since_lab = np.array(since_names, dtype=object)[np.digitize(since, since_edges)]
    frac = np.clip(t_run_s / max(run_s, 1e-9), 0, 1)
    tir_names = ["0-20 %", "20-40 %", "40-60 %", "60-80 %", "80-100 %"]
    tir = np.array(tir_names, dtype=object)[np.clip((frac * 5).astype(int), 0, 4)]
    return KnobLabels({
        "regime": regime.astype(str), "direction": direction.astype(str),
        "other_knob": other.astype(str), "speed": speed.astype(str),
        "since_reversal": since_lab.astype(str), "time_in_run": tir.astype(str)})


@dataclass(frozen=True)
class BinRow:
    factor: str
    bin: str
    share_rows: float
    share_gap: float
    rms: float
    mean: float


def breakdown(resid: Sequence[NDArray[np.float64]], labels: Sequence[KnobLabels],
              weight: float = 1.0) -> tuple[dict[str, float], list[BinRow]]:
    """Per factor the share of the gap it holds, and per bin its share of rows and of the gap.

    ``resid`` and ``labels`` are parallel lists (one entry per knob-channel and series).
    """
    if not resid:  # no held-out row measures this channel group
        return {"constant offset": 0.0, **{f: 0.0 for f in FACTORS}}, []
    r = np.concatenate([np.asarray(x, dtype=float) for x in resid]) * weight
    total = float(np.sum(r * r))
    offset = float(r.size * r.mean() ** 2) if r.size else 0.0
    shares: dict[str, float] = {"constant offset": offset / total if total > 0 else 0.0}
    rows: list[BinRow] = []
    for factor in FACTORS:
        lab = np.concatenate([lb.labels[factor] for lb in labels])
        removed = 0.0
        for b in sorted(set(lab.tolist())):
            m = lab == b
            rb = r[m]
            mean = float(rb.mean())
            removed += float(m.sum()) * mean * mean
            rows.append(BinRow(factor, b, float(m.mean()),
                               float(np.sum(rb * rb) / total) if total > 0 else 0.0,
                               float(np.sqrt(np.mean(rb * rb))) / weight, mean / weight))
        shares[factor] = (removed - offset) / total if total > 0 else 0.0
    return shares, rows
