"""Error figures, noise floor, block bootstrap and residual whiteness."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray
from scipy import stats


def rmse(err: NDArray[np.float64]) -> float:
    """Root mean square of the finite errors (NaN marks a channel that was not measured)."""
    e = err[np.isfinite(err)]
    return float(np.sqrt(np.mean(np.square(e)))) if e.size else float("nan")


def ptpe(err: NDArray[np.float64]) -> float:
    """Peak-to-peak error: highest minus lowest error (the paper's PTPE)."""
    e = err[np.isfinite(err)]
    return float(np.max(e) - np.min(e)) if e.size else float("nan")


def noise_variance(y: NDArray[np.float64]) -> float:
    """White-noise variance of a measured signal from its second differences (robust, MAD).

    For a smooth signal plus white noise of variance s^2, the second difference has variance
    6 s^2. Quantised signals whose differences are mostly zero fall back to the quantisation
    floor (step^2 / 12).
    """
    d2 = np.diff(y, 2)
    if d2.size < 8:
        return 1e-12
    mad = float(np.median(np.abs(d2 - np.median(d2))))
    var = (1.4826 * mad) ** 2 / 6.0
    steps = np.abs(np.diff(y))
    steps = steps[steps > 1e-12]
    floor = float(np.min(steps)) ** 2 / 12.0 if steps.size else 1e-12
    return max(var, floor, 1e-12)


def bootstrap_ratio_ci(num: NDArray[np.float64], den: NDArray[np.float64], seed: int,
                       n_boot: int = 2000, level: float = 0.9) -> tuple[float, float, float]:
    """Point estimate and percentile CI of sum(num)/sum(den), resampling blocks with replacement."""
    num = np.asarray(num, dtype=float)
    den = np.asarray(den, dtype=float)
    point = float(num.sum() / den.sum()) if den.sum() != 0 else float("nan")
    if len(num) < 2:
        return point, float("nan"), float("nan")
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, len(num), size=(n_boot, len(num)))
    d = den[idx].sum(axis=1)
    ratios = num[idx].sum(axis=1) / np.where(d == 0, np.nan, d)
    lo, hi = np.nanpercentile(ratios, [50 * (1 - level), 50 * (1 + level)])
    return point, float(lo), float(hi)


def ljung_box(resid: NDArray[np.float64], lags: int = 20) -> tuple[float, float]:
    """Ljung-Box Q over ``lags`` autocorrelations and its chi-square p-value (white: p large)."""
    x = np.asarray(resid, dtype=float)
    x = x - x.mean()
    n = len(x)
    denom = float(np.dot(x, x))
    if n <= lags + 1 or denom == 0:
        return float("nan"), float("nan")
    acf = np.array([np.dot(x[:-k], x[k:]) / denom for k in range(1, lags + 1)])
    q = float(n * (n + 2) * np.sum(acf**2 / (n - np.arange(1, lags + 1))))
    return q, float(stats.chi2.sf(q, lags))


def pooled_ljung_box(segments: Sequence[NDArray[np.float64]], lags: int = 20,
                     max_points: int = 4000) -> tuple[float, float]:
    """Ljung-Box on residual segments thinned to at most ``max_points`` rows in all.

    Thinning keeps the lags meaningful (about one lag per original-rate stride) and the test
    cheap; segments are concatenated after thinning.
    """
    total = sum(len(s) for s in segments)
    if total == 0:
        return float("nan"), float("nan")
    stride = max(total // max_points, 1)
    pieces = [s[::stride] for s in segments if len(s)]
    return ljung_box(np.concatenate(pieces), lags)


def unit_spread(values: NDArray[np.float64], noise: NDArray[np.float64]
                ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Mean over units (axis 0) of per-unit ``values`` with the variance of each (``noise``):
    the mean, its noise, and the allowance a further unit has about it beyond its own noise,
    as a variance: the square of a one-sided 95 % prediction bound from the units' spread
    (sample variance less their mean noise, times 1 + 1/n for the mean's uncertainty, times
    Student's t at n - 1 degrees of freedom squared: a unit's constants move the model's
    contrast along few directions, so its deviation is bounded like one normal value, not
    averaged over many points); 0 from one unit."""
    n = values.shape[0]
    mean = values.mean(axis=0)
    own = noise.mean(axis=0)
    if n < 2:
        return mean, own, np.zeros_like(mean)
    bound = float(stats.t.ppf(0.95, n - 1)) ** 2 * (1.0 + 1.0 / n)
    spread = np.maximum(values.var(axis=0, ddof=1) - own, 0.0) * bound
    return mean, own / n, spread
