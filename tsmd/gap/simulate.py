"""Replay knob motion through a plant, and the motor-current map from knob torque.

The plant is driven directly with the recorded actual knob angles (no CAN, no drive model): the
gap diagnosis compares physics, not the bus. Simulating every row of a 250 Hz recording costs a
Python call per row, so rows the fit does not score are thinned (see :func:`eval_grid`).
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import signal

from simrig.plant import Plant, as_plant_step
from tsmd.gap.errors import GapError

PlantFactory = Callable[[dict[str, Any]], Plant]
"""Builds a fresh plant from the base parameters being fitted (the others are fixed)."""


SUBSTEPS = 16
"""A step an implicit plant (coilpipe) does not converge on is taken again in this many equal
parts of time and knob travel, from the plant's state before it."""
_PLANT_FAILURES = (ArithmeticError, np.linalg.LinAlgError)


def simulate(plant: Plant, t_s: NDArray[np.float64],
             knob_deg: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Step ``plant`` through the knob angles at times ``t_s``; return tip (N,2), torque (N,2).

    A plant that fails on a step (thinned replay rows are longer steps than the recording's)
    is replayed again keeping a copy of its state before every step, and a failing step is
    retried in parts; only if that fails too does the replay stop, with one line
    (:class:`GapError`). Plants that never fail pay nothing for this."""
    knob = np.asarray(knob_deg, dtype=float)
    try:
        return _replay(plant, t_s, knob, guarded=False)
    except _PLANT_FAILURES:
        return _replay(plant, t_s, knob, guarded=True)


def _replay(plant: Plant, t_s: NDArray[np.float64], knob: NDArray[np.float64],
            guarded: bool) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    n = len(t_s)
    tip = np.empty((n, 2))
    torque = np.empty((n, 2))
    plant.reset()
    dt = np.diff(t_s, prepend=t_s[0] - (t_s[1] - t_s[0] if n > 1 else 0.01))
    for k in range(n):
        saved = copy.deepcopy(plant) if guarded else None
        try:
            out = as_plant_step(plant.step(float(dt[k]), knob[k]))
        except _PLANT_FAILURES:
            if saved is None:
                raise
            plant = saved
            out = _in_parts(plant, float(dt[k]), knob[max(k - 1, 0)], knob[k], float(t_s[k]))
        tip[k] = out.tip_deg
        torque[k] = out.knob_torque_Nm
    return tip, torque


def _in_parts(plant: Plant, dt_s: float, start_deg: NDArray[np.float64],
              end_deg: NDArray[np.float64], t_s: float) -> Any:
    """One replay step taken in :data:`SUBSTEPS` equal parts of time and knob travel."""
    out = None
    try:
        for i in range(1, SUBSTEPS + 1):
            knob = start_deg + (end_deg - start_deg) * (i / SUBSTEPS)
            out = as_plant_step(plant.step(dt_s / SUBSTEPS, knob))
    except _PLANT_FAILURES as exc:
        raise GapError(f"the simulator plant failed at t = {t_s:.3f} s, even in "
                       f"{SUBSTEPS} parts: {exc}") from None
    return out


def turning_points(x: NDArray[np.float64], min_travel: float) -> NDArray[np.int64]:
    """Rows where a signal reverses after moving at least ``min_travel`` (peaks and valleys).

    A rate-independent hysteresis's state is set by the sequence of its input's extremes, so a
    thinned simulation stays exact only if it keeps them; jitter under ``min_travel`` (encoder
    noise, a knob at rest) is not a reversal.
    """
    out: list[int] = []
    if len(x) < 3:
        return np.zeros(0, dtype=np.int64)
    ext_i, ext_v, rising = 0, float(x[0]), 0  # running extreme since the last turn; 0 = unknown
    for i, v in enumerate(np.asarray(x, dtype=float).tolist()):
        if (rising >= 0 and v > ext_v) or (rising <= 0 and v < ext_v):
            if rising == 0 and abs(v - x[0]) >= min_travel:
                rising = 1 if v > x[0] else -1
            ext_i, ext_v = i, v
        elif rising != 0 and abs(v - ext_v) >= min_travel:
            out.append(ext_i)
            rising, ext_i, ext_v = -rising, i, v
    return np.asarray(out, dtype=np.int64)


def fit_grid(n: int, stride: int, knob_deg: NDArray[np.float64] | None = None,
             min_travel_deg: float = 0.5) -> NDArray[np.int64]:
    """Every ``stride``-th row, the last, and every knob reversal: what the fits simulate.

    Without the reversals a thinned grid cuts the tops off fast sweeps and the simulated
    hysteresis loop is narrower than the one driven.
    """
    idx = np.arange(0, n, max(stride, 1))
    if idx[-1] != n - 1:
        idx = np.append(idx, n - 1)
    if knob_deg is not None and stride > 1:
        turns = [turning_points(knob_deg[:, j], min_travel_deg) for j in range(knob_deg.shape[1])]
        idx = np.union1d(idx, np.concatenate([idx, *turns]))
    return idx


def eval_grid(held_out: NDArray[np.bool_], stride: int,
              held_out_stride: int = 1,
              knob_deg: NDArray[np.float64] | None = None) -> NDArray[np.int64]:
    """Every ``held_out_stride``-th held-out row plus the fit grid (to carry the plant's state).

    A quasi-static plant gives the same state at a row whether the rows before it were stepped
    one by one or thinned (as long as the knob reversals are kept), so training rows need not
    all be simulated to score held-out ones.
    """
    n = len(held_out)
    keep = np.zeros(n, dtype=bool)
    ho = np.flatnonzero(held_out)
    keep[ho[:: max(held_out_stride, 1)]] = True
    keep[fit_grid(n, stride, knob_deg)] = True
    return np.flatnonzero(keep)


def smooth_velocity(t_s: NDArray[np.float64], x: NDArray[np.float64],
                    window_s: float = 0.06) -> NDArray[np.float64]:
    """Knob velocity (deg/s) by central differences, then a moving average over ``window_s``."""
    if len(t_s) < 3:
        return np.zeros_like(x)
    v = np.gradient(x, t_s, axis=0)
    dt = float(np.median(np.diff(t_s)))
    w = max(round(window_s / dt), 1)
    if w <= 1:
        return v
    kernel = np.ones(w) / w
    if v.ndim == 1:
        return np.convolve(v, kernel, mode="same")
    return np.column_stack([np.convolve(col, kernel, mode="same") for col in v.T])


def lowpass(t_s: NDArray[np.float64], x: NDArray[np.float64], tau_s: float) -> NDArray[np.float64]:
    """First-order lag with time constant ``tau_s``, exact for uneven steps (x is (N,) or (N,k))."""
    if tau_s <= 0:
        return x.copy()
    dts = np.diff(t_s)
    if len(dts) and np.ptp(dts) <= 1e-6 * float(dts.mean()):
        a0 = float(np.exp(-dts.mean() / tau_s))
        zi = a0 * x[0] if x.ndim == 1 else (a0 * x[0])[None, :]
        y_u, _ = signal.lfilter([1.0 - a0], [1.0, -a0], x, axis=0, zi=np.atleast_1d(zi))
        return np.asarray(y_u)
    a = np.exp(-dts / tau_s)
    y = np.empty_like(x)
    y[0] = x[0]
    for k in range(1, len(x)):
        y[k] = a[k - 1] * y[k - 1] + (1.0 - a[k - 1]) * x[k]
    return y


def current_regressors(torque_Nm: NDArray[np.float64], vel_deg_s: NDArray[np.float64],
                       v0_deg_s: float) -> NDArray[np.float64]:
    """Columns (torque, 1, tanh(v/v0), v) for one knob: the base current map's regressors.

    The motor-current map of the gap diagnosis (not the drive's) is
    ``i = gain*torque + offset + coulomb*tanh(v/v0) + viscous*v``, fitted per knob by linear
    least squares; ``tanh`` smooths the Coulomb sign.
    """
    return np.column_stack([torque_Nm, np.ones_like(torque_Nm),
                            np.tanh(vel_deg_s / v0_deg_s), vel_deg_s])
