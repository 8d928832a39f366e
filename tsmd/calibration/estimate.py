"""Per-grid-point estimates with an uncertainty, and the gate that decides what to re-sweep.

Each half-cycle gives one value of a parameter; a sweep of two cycles gives two. Two values say
little about their own scatter, so the scatter of one half-cycle's value is pooled over every
sweep and both sides of the same kind of parameter (dead-zone edges; backlashes: they share the
sensor, the catheter and the detector), and each sweep's own disagreement is weighed against
that pool:

* ``sigma_pool``: robust pooled standard deviation of one half-cycle's value (the median of the
  sweeps' variances, each scaled by the median of its chi-square distribution, so that one sweep
  that disagrees does not inflate every other sweep's uncertainty);
* per sweep: ``s^2 = (k_own s_own^2 + k_prior sigma_pool^2) / (k_own + k_prior)`` (the pool acts
  as a prior worth ``k_prior`` degrees of freedom, its own up to 6), and the 95 % half-width
  ``u95 = t(0.975, k_own + k_prior) s / sqrt(n)``.

The gate judges ``u95`` by its cost on the tip: outside the dead zone the tip turns ``omega``
degrees per knob degree, so a parameter off by ``u95`` puts the compensated tip off by
``omega u95``. A grid point whose tip cost exceeds ``max_tip_error_deg`` is swept again.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from scipy import stats

from tsmd.calibration.signal import walsh_median
from tsmd.calibration.sweep_result import PARAMETERS, SweepResult

MIN_ROBUST = 4
"""From this many half-cycles on, a sweep's own scatter is taken robustly (MAD)."""
WALSH_EFFICIENCY = 0.955
"""Variance of the mean over that of :func:`walsh_median`, normal scatter (3/pi)."""
RESOLUTION_DEG = 0.25
"""One half-cycle's value cannot be surer than the identification's angle grid."""


@dataclass(frozen=True)
class Estimate:
    """One parameter at one grid point: value, 95 % half-width, how many half-cycles."""

    value: float
    u95_deg: float
    n: int
    spread_deg: float
    sigma_deg: float = math.nan
    """One half-cycle's scatter behind ``u95_deg`` (own and pooled, blended)."""
    dof: int = 0
    """Degrees of freedom of ``sigma_deg``."""
    offset_u95_deg: float = 0.0
    """The 95 % half-width of the product's reading offset subtracted from the values (part of
    ``u95_deg``; no re-sweep narrows it)."""
    unit_u95_deg: float = 0.0
    """The 95 % half-width of what the current cannot show of this unit (the product's sample's,
    :mod:`tsmd.calibration.unit_part`, or a backlash's share of the gap to the release line:
    :meth:`SweepResult.unit_u95_deg`). Not part of ``u95_deg``,
    which the gate judges by what sweeps can narrow; part of :attr:`reported_u95_deg`."""

    @property
    def reported_u95_deg(self) -> float:
        """The 95 % half-width a calibration reports: ``u95_deg`` and ``unit_u95_deg`` in
        quadrature."""
        return math.hypot(self.u95_deg, self.unit_u95_deg)

    def tip_cost_deg(self, omega: float) -> float:
        """What an error of ``u95_deg`` costs on the tip once compensated."""
        return abs(omega) * self.u95_deg

    def tip_cost_with_deg(self, omega: float, more: int) -> float:
        """The tip cost expected once ``more`` half-cycles of the same scatter are pooled in
        (what a re-sweep would buy); infinite while no half-cycle gave a value."""
        if self.n == 0 or not math.isfinite(self.sigma_deg):
            return math.inf
        return abs(omega) * math.hypot(half_width_deg(self.sigma_deg, self.n + more,
                                                      self.dof + more), self.offset_u95_deg)


@dataclass(frozen=True)
class EstimateOptions:
    """The pooling and the gate."""

    max_prior_dof: int = 6
    """Weight of the pooled scatter against a sweep's own, in degrees of freedom: the pool's
    own (one per sweep of two values), at most this many, so that a sweep whose cycles
    disagree is not talked out of it by the others."""
    max_tip_error_deg: float = 3.0
    """Largest 95 % tip error a parameter's uncertainty may cost (re-sweep above): the
    accuracy target of 2 knob deg at the simulated catheter's slope omega = 1.32, rounded up;
    on a steeper catheter the same knob uncertainty costs more and is swept again sooner."""
    min_sigma_deg: float = RESOLUTION_DEG


def half_width_deg(sigma_deg: float, n: int, dof: int) -> float:
    """95 % half-width of the robust mean (:func:`walsh_median`) of ``n`` half-cycles whose
    scatter is ``sigma_deg``."""
    t = float(stats.t.ppf(0.975, dof))
    # From three values on it is a little less efficient than a mean (0.955 on normal scatter).
    efficiency = math.sqrt(1.0 / WALSH_EFFICIENCY) if n >= 3 else 1.0
    return t * efficiency * sigma_deg / math.sqrt(n)


def _chi2_median_ratio(dof: int) -> float:
    """Median of chi2(dof)/dof: a sample variance's typical ratio to the true variance."""
    return float(stats.chi2.ppf(0.5, dof) / dof)


KINDS: dict[str, tuple[str, ...]] = {
    "dead-zone edge": ("dead_zone_pos_deg", "dead_zone_neg_deg"),
    "backlash": ("backlash_pos_deg", "backlash_neg_deg"),
}
"""Parameters found by the same detector, whose half-cycle scatter is pooled together."""


def pooled_sigma(results: Sequence[SweepResult], names: Sequence[str],
                 min_sigma_deg: float = RESOLUTION_DEG) -> tuple[float, int]:
    """Robust scatter of one half-cycle's value over sweeps and parameters, and its degrees of
    freedom."""
    scaled: list[float] = []
    dof = 0
    for r in results:
        for name in names:
            v = np.asarray(r.values.get(name, ()), dtype=float)
            if v.size >= 2:
                scaled.append(float(np.var(v, ddof=1)) / _chi2_median_ratio(v.size - 1))
                dof += v.size - 1
    if not scaled:
        return math.nan, 0
    return max(math.sqrt(float(np.median(scaled))), min_sigma_deg), dof


def estimate(values: Sequence[float], sigma_pool: float, pool_dof: int = 0,
             options: EstimateOptions | None = None, offset_u95_deg: float = 0.0) -> Estimate:
    """Robust mean of the half-cycles' values and its 95 % half-width (see the module
    docstring), the reading offset's half-width ``offset_u95_deg`` added in quadrature."""
    opts = options or EstimateOptions()
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return Estimate(math.nan, math.inf, 0, math.nan)
    k_own = v.size - 1
    own_var = float(np.var(v, ddof=1)) if k_own else 0.0
    if v.size >= MIN_ROBUST:
        # Robust scale: one stray half-cycle among several must not make the point uncertain.
        own_var = min(own_var, (1.4826 * float(np.median(np.abs(v - np.median(v))))) ** 2)
    k_prior = min(pool_dof, opts.max_prior_dof) if math.isfinite(sigma_pool) else 0
    if k_own + k_prior == 0:
        return Estimate(float(v[0]), math.inf, 1, 0.0, offset_u95_deg=offset_u95_deg)
    prior_var = sigma_pool ** 2 if k_prior else 0.0
    var = (k_own * own_var + k_prior * prior_var) / (k_own + k_prior)
    sigma = max(math.sqrt(var), opts.min_sigma_deg)
    half = math.hypot(half_width_deg(sigma, v.size, k_own + k_prior), offset_u95_deg)
    return Estimate(walsh_median(v), half, int(v.size), float(np.ptp(v)), sigma, k_own + k_prior,
                    offset_u95_deg)


def point_estimates(results: Sequence[SweepResult],
                    options: EstimateOptions | None = None) -> list[dict[str, Estimate]]:
    """Every parameter's estimate for each sweep, the scatter pooled per kind of parameter over
    all the sweeps given (both knobs: same sensor, same detector, same catheter)."""
    opts = options or EstimateOptions()
    pools = {name: pooled_sigma(results, names, opts.min_sigma_deg)
             for names in KINDS.values() for name in names}
    return [{name: replace(estimate(r.values.get(name, ()), *pools[name], options=opts,
                                    offset_u95_deg=r.offset_u95_deg.get(name, 0.0)),
                           unit_u95_deg=r.unit_u95_deg(name))
             for name in PARAMETERS} for r in results]


def too_uncertain(estimates: dict[str, Estimate], omega: float,
                  options: EstimateOptions | None = None) -> list[str]:
    """Parameters whose uncertainty costs more on the tip than the gate allows (or missing)."""
    opts = options or EstimateOptions()
    return [name for name, e in estimates.items()
            if not e.tip_cost_deg(omega) <= opts.max_tip_error_deg]
