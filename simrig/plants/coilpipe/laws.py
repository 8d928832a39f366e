"""Constitutive laws of the coil-pipe plant, vectorised, each with its derivative for Newton.

- a cable under tension only, with a quadratic toe (strands settle) before its linear stiffness;
- a gear gap: the same law on both flanks, shifted by half the gap;
- LuGre friction with a load-dependent normal force (Canudas de Wit et al. 1995, the normalised
  bristle form): dz/dt = v/delta - |v|/delta * z/s(v), s(v) = 1 + (ratio-1) exp(-(v/v_s)^2),
  F = N z + c v; discretised implicitly in z so any step from 0.1 to 4 ms is stable.
  (Velocity weakening without inertia has no unique quasi-static answer; see ``lugre``.)
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def cable(e_mm: Array, k_N_per_mm: Array, toe_mm: Array) -> tuple[Array, Array]:
    """Tension (N) and its slope of a cable stretched by ``e_mm`` beyond its slack: quadratic
    over the toe, linear after it."""
    stretch = np.maximum(e_mm, 0.0)
    toe = np.minimum(stretch, toe_mm)
    slope = k_N_per_mm * (toe / toe_mm)
    tension = slope * (0.5 * toe) + k_N_per_mm * (stretch - toe)
    return tension, slope


def stribeck(v_mm_s: Array, stribeck_ratio: Array, stribeck_speed_mm_s: Array) -> Array:
    """Steady sliding friction over its kinetic level: static at rest, kinetic when fast."""
    u = v_mm_s / stribeck_speed_mm_s
    return 1.0 + (stribeck_ratio - 1.0) * np.exp(-u * u)


def lugre(z: Array, d_mm: Array, presliding_mm: Array, level: Array) -> tuple[Array, Array]:
    """The bristle state after a displacement ``d_mm`` (implicit in z) at the Stribeck ``level``
    of the previous step's speed, and its derivative with respect to ``d_mm``. The level lags
    one step: within a step the friction is then monotone in the displacement, so the implicit
    step has one solution even where the friction weakens with speed."""
    c = 1.0 / (presliding_mm * level)
    den = 1.0 + c * np.abs(d_mm)
    num = z + d_mm / presliding_mm
    z1 = num / den
    dz = (den / presliding_mm - num * c * np.sign(d_mm)) / (den * den)
    return z1, dz
