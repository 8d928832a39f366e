"""The ratestate plant's laws: the shaft's wrap profile and the contacts' ageing friction."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

CURVE_WIDTH = 0.12
"""Width (share of the shaft, one standard deviation) of a curve of the shaft."""


def wrap_profile_rad(wrap_deg: float, nodes: int, curve_position: float, curve_share: float,
                     extra_curve_deg: float = 0.0) -> FloatArray:
    """Wrap (rad) each of ``nodes`` equal shaft elements carries: ``1 - curve_share`` of the
    wrap spread evenly, ``curve_share`` in a Gaussian curve at ``curve_position``; an extra bend
    of the whole shaft (``extra_curve_deg``, e.g. a curved patient path) mid-shaft."""
    s = (np.arange(nodes) + 0.5) / nodes
    curve = _bump(s, curve_position)
    extra = _bump(s, 0.5)
    wrap = wrap_deg * ((1.0 - curve_share) / nodes + curve_share * curve) + extra_curve_deg * extra
    return np.radians(wrap)


def _bump(s: FloatArray, centre: float) -> FloatArray:
    """A Gaussian over the elements' centres ``s``, normalised to sum 1."""
    g = np.exp(-0.5 * ((s - centre) / CURVE_WIDTH) ** 2)
    return g / g.sum()


def aged_friction(mu0: FloatArray, b: FloatArray, age_s: FloatArray, cutoff_s: FloatArray
                  ) -> FloatArray:
    """Friction coefficient of contacts of age ``age_s`` (Dieterich's state variable, s):
    ``mu0 + b ln(1 + age / cutoff)``. The age grows while a contact sticks (static friction
    rises with dwell time) and falls to ``D_c / v`` while it slides (kinetic friction falls
    with speed)."""
    return mu0 + b * np.log1p(age_s / cutoff_s)


def age_after(age_s: FloatArray, slip_mm: FloatArray, dt_s: float, dc_mm: FloatArray
              ) -> FloatArray:
    """Dieterich's ageing law ``d(age)/dt = 1 - |v| age / D_c`` integrated exactly over a step
    of ``dt_s`` with the slip ``slip_mm`` made at a constant rate: with ``x = slip / D_c``,
    ``age' = age e^-x + dt (1 - e^-x) / x`` (``dt`` added while stuck, ``x -> 0``)."""
    x = np.maximum(np.abs(slip_mm) / dc_mm, 1e-12)
    decay = np.expm1(-x)
    return np.asarray(age_s * (1.0 + decay) - dt_s * decay / x, dtype=float)
