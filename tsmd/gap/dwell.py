"""Creep from dwells: the residual's slope with the tendon loaded minus unloaded.

A drifting tracker or a slow base mismatch drifts in both dwells and cancels in the difference;
creep under tension drifts only in the loaded one. Creep under tension is read on the motor
currents (the tension the held knob needs relaxes as the tendon creeps): at a held knob the tip
also moves for reasons of the bending section, e.g. a viscoelastic cover that creeps on under
load and springs back slowly in the unloaded dwell (the coilpipe plant, docs/gap.md "Session
11"), which is no creep of the tendon and larger in the unloaded dwell than in the loaded one.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import stats

FloatArray = NDArray[np.float64]


@dataclass
class Drift:
    """Per dwell pair (loaded, unloaded) and channel: slope difference and its variance."""

    diff: FloatArray  # (pairs, channels) loaded minus unloaded slope
    var: FloatArray
    span_s: FloatArray  # (pairs,) how long each loaded dwell is compared


CREEP_CHANNELS: tuple[int, int] = (2, 3)
"""The residual's channels the creep test reads: the two motor currents (see the module)."""


def dwell_slope(t: FloatArray, y: FloatArray) -> tuple[float, float]:
    """Least-squares slope and its variance, inflated for correlated residuals."""
    tc = t - t.mean()
    sxx = float((tc**2).sum())
    slope = float((tc * (y - y.mean())).sum() / sxx)
    r = y - y.mean() - slope * tc
    rho = float((r[1:] * r[:-1]).sum() / max(float((r**2).sum()), 1e-300))
    rho = min(max(rho, 0.0), 0.95)
    var = float((r**2).sum()) / max(len(r) - 2, 1) / sxx * (1.0 + rho) / (1.0 - rho)
    return slope, var


def drift_stat(drifts: Sequence[Drift]) -> tuple[float, float, float]:
    """Chi-square of the loaded-minus-unloaded slopes; returns (chi2, dof, p)."""
    used = [d.var > 0 for d in drifts]  # a channel that never changes has no slope
    chi = sum(float((d.diff[u] ** 2 / d.var[u]).sum()) for d, u in zip(drifts, used, strict=True))
    dof = float(sum(int(u.sum()) for u in used))
    return chi, dof, float(stats.chi2.sf(chi, dof)) if dof else 1.0


def drift_size(drifts: Sequence[Drift]) -> float:
    """How far creep moves a channel over one loaded dwell beyond the slopes' noise: the RMS
    loaded-minus-unloaded slope less its variance, times the dwell's compared length (the
    channels' unit, here A)."""
    diff = np.concatenate([d.diff.ravel() for d in drifts]) if drifts else np.zeros(0)
    if not diff.size:
        return float("nan")
    var = np.concatenate([d.var.ravel() for d in drifts])
    span = float(np.median(np.concatenate([d.span_s for d in drifts])))
    return float(np.sqrt(max(float(np.mean(diff**2 - var)), 0.0)) * span)


def drift_shrink(train: Sequence[Drift], held: Drift) -> float:
    """Share of the held-out configuration's creep drift (above its noise) predicted by the
    drift per dwell and channel of the training configurations."""
    if not train:
        return float("nan")
    w = 1.0 / np.maximum(np.mean([d.var.mean(axis=0) for d in (*train, held)], axis=0), 1e-300)
    excess = float(((held.diff**2 - held.var) * w).sum())
    if excess <= float((held.var * w).sum()):  # no drift above its noise
        return float("nan")
    pred = np.mean([d.diff for d in train], axis=0)
    resid = float((((held.diff - pred) ** 2 - held.var) * w).sum())
    return min(1.0 - resid / excess, 1.0)
