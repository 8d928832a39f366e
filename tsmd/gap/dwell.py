"""Creep from dwells: the residual's slope with the tendon loaded minus unloaded.

A drifting tracker or a slow base mismatch drifts in both dwells and cancels in the difference;
creep under tension drifts only in the loaded one. Creep under tension is read on the motor
currents (the tension the held knob needs relaxes as the tendon creeps) and, since session 21,
on the tips' *relaxation*: a tendon that creeps at its far end (a pull-ring crimp slipping, the
blind jawcrimp plant) lets the tip fall back toward its unloaded position at a held knob while
a friction node holds most of the tension the motor feels (0.15 deg of tip, 2 mA over a dwell).
At a held knob the tip also moves for reasons of the bending section, e.g. a viscoelastic cover
that creeps on under load and springs back slowly in the unloaded dwell (the coilpipe plant,
docs/gap.md "Session 11"): that moves the loaded tip on, away from its unloaded position, so
only the part of the tip's drift toward it is read (:func:`tip_relaxation`).
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
    load_sign: FloatArray | None = None
    """(pairs, 2): the side each knob's loaded dwell loads (the sign of its knob angle)."""

    def columns(self, part: slice) -> Drift:
        """The same pairs, only the channels in ``part``."""
        return Drift(self.diff[:, part], self.var[:, part], self.span_s)


CREEP_CHANNELS: tuple[int, int] = (2, 3)
"""The residual's channels whose drift the creep test reads as such: the two motor currents
(see the module); a :class:`Drift` holds them in its first two columns."""

RELAX_CHANNELS: tuple[int, int] = (0, 1)
"""The residual's channels read for their relaxation only (:func:`tip_relaxation`): the two
tips; a :class:`Drift` holds them in its last two columns."""

CURRENT_COLUMNS = slice(0, 2)
RELAX_COLUMNS = slice(2, 4)
"""Where a :class:`Drift` holds the currents' drift (A/s) and the tips' relaxation (deg/s)."""


@dataclass(frozen=True)
class CreepReading:
    """The creep test's verdict from one of its two readings (currents or tips)."""

    p: float
    """Its chi-square's p, doubled (two readings tried)."""
    shrinks: list[float]
    """Per configuration held out, the share of its drift the others predict."""
    current_size_A: float
    tip_size_deg: float
    material: bool
    """The deciding reading's drift at least one sample's noise of its channel."""


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


def tip_relaxation(t_loaded: FloatArray, tip_loaded: FloatArray, t_unloaded: FloatArray,
                   tip_unloaded: FloatArray, load_sign: float) -> tuple[float, float]:
    """How fast a tip falls back toward its unloaded position over a loaded dwell (deg/s, >= 0)
    and that slope's variance. ``load_sign``: the side the dwell loads (the sign of its knob
    angle). Read beyond the unloaded dwell's slope (a drifting tracker cancels) and no faster
    than the loaded slope itself: a tip moving on under load, or drifting only at rest (a
    cover springing back), is no tendon's creep and reads 0."""
    sl, vl = dwell_slope(t_loaded, tip_loaded)
    su, vu = dwell_slope(t_unloaded, tip_unloaded)
    relax = min(-load_sign * (sl - su), -load_sign * sl)
    return max(relax, 0.0), vl + vu


def drift_stat(drifts: Sequence[Drift]) -> tuple[float, float, float]:
    """Chi-square of the loaded-minus-unloaded slopes; returns (chi2, dof, p)."""
    used = [d.var > 0 for d in drifts]  # a channel that never changes has no slope
    chi = sum(float((d.diff[u] ** 2 / d.var[u]).sum()) for d, u in zip(drifts, used, strict=True))
    dof = float(sum(int(u.sum()) for u in used))
    return chi, dof, float(stats.chi2.sf(chi, dof)) if dof else 1.0


def drift_size(drifts: Sequence[Drift], columns: slice = CURRENT_COLUMNS) -> float:
    """How far creep moves the channels in ``columns`` (default the currents, A; the tips'
    relaxation :data:`RELAX_COLUMNS`, deg) over one loaded dwell beyond the slopes' noise: the
    RMS loaded-minus-unloaded slope less its variance, times the dwell's compared length."""
    diff = np.concatenate([d.diff[:, columns].ravel() for d in drifts]) if drifts else np.zeros(0)
    if not diff.size:
        return float("nan")
    var = np.concatenate([d.var[:, columns].ravel() for d in drifts])
    span = float(np.median(np.concatenate([d.span_s for d in drifts])))
    return float(np.sqrt(max(float(np.mean(diff**2 - var)), 0.0)) * span)


def creep_reading(drifts: Sequence[Drift], current_noise_A: float | None,
                  tip_noise_deg: float | None, alpha: float) -> CreepReading:
    """Read the currents' drift and the tips' relaxation apart, each with its chi-square and
    size rule (noise-only tips would dilute a current test's power, and a tip relaxing with
    its current adds none). The reading that decides: the more significant of those that
    pass (p, doubled for the two readings, below ``alpha``, size material), else the more
    significant of both; without a noise figure a reading's size is material."""
    readings = []
    for part, noise in ((CURRENT_COLUMNS, current_noise_A), (RELAX_COLUMNS, tip_noise_deg)):
        own = [d.columns(part) for d in drifts]
        size = drift_size(own, slice(None))
        material = noise is None or not np.isfinite(size) or size >= noise
        p = min(2.0 * drift_stat(own)[2], 1.0)
        readings.append((not (material and p < alpha), p, material, own))
    _, p, material, own = min(readings, key=lambda r: (r[0], r[1]))
    return CreepReading(p, [drift_shrink(own[:i] + own[i + 1:], own[i])
                            for i in range(len(own))],
                        drift_size(drifts, CURRENT_COLUMNS), drift_size(drifts, RELAX_COLUMNS),
                        material)


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
