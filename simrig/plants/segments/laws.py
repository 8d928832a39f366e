"""Constitutive laws of the segments plant, vectorised over any array shape.

- ``recruit``: a tendon segment that carries no compression and whose stiffness grows smoothly
  from 0 to EA/l over a toe (crimp straightening, fibre recruitment): slack as a smooth contact.
- ``presliding_*``: the elasto-plastic friction state of one contact (Dupont, Hayward, Armstrong
  and Altpeter 2002): purely elastic below ``stick`` x the presliding displacement, then a smooth
  transition to sliding; rate-independent, so the plant's tick does not change the loops.
- ``bouc_wen_*``: the bending section's own hysteresis, a Bouc-Wen state of exponent 2.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def recruit(stretch_m: Array, toe_m: Array, stiffness_N_per_m: Array) -> tuple[Array, Array]:
    """(tension N, tangent stiffness N/m) of segments stretched by ``stretch_m``.

    The stiffness follows the smoothstep 3x^2 - 2x^3 of x = stretch/toe over the toe, so both
    tension and stiffness are continuous: the implicit step sees no jump when a tendon engages.
    """
    x = np.minimum(np.maximum(stretch_m / toe_m, 0.0), 1.0)
    in_toe = x * x * (3.0 - 2.0 * x)
    tension = np.where(stretch_m >= toe_m, stiffness_N_per_m * (stretch_m - 0.5 * toe_m),
                       stiffness_N_per_m * toe_m * x ** 3 * (1.0 - 0.5 * x))
    return tension, stiffness_N_per_m * in_toe


def _transition(z_m: Array, presliding_m: Array, stick: Array) -> Array:
    """The elasto-plastic model's alpha(z): 0 in stick, a half cosine up to 1 at full
    presliding, 1 beyond."""
    t = (np.abs(z_m) / presliding_m - stick) / (1.0 - stick)
    return 0.5 - 0.5 * np.cos(np.pi * np.minimum(np.maximum(t, 0.0), 1.0))


def presliding_slope(z_m: Array, direction: Array, presliding_m: Array, stick: Array) -> Array:
    """dz/du for motion in ``direction`` (+1, -1, 0): 1 in stick or when moving back."""
    same = (direction * z_m) > 0.0
    return 1.0 - same * _transition(z_m, presliding_m, stick) * np.abs(z_m) / presliding_m


def presliding_update(z_m: Array, du_m: Array, presliding_m: Array, stick: Array) -> Array:
    """The contact state after a travel ``du_m``: dz/du = 1 - alpha(z) |z|/z_max when moving
    the way z points, 1 when moving back; exact for alpha frozen at its start value (callers
    keep ``du_m`` below half the presliding displacement)."""
    alpha = ((du_m * z_m) > 0.0) * _transition(z_m, presliding_m, stick)
    x = alpha * np.abs(du_m) / presliding_m
    phi = np.where(x > 1e-6, -np.expm1(-x) / np.maximum(x, 1e-300), 1.0 - 0.5 * x)
    z = z_m + (1.0 - alpha * np.abs(z_m) / presliding_m) * du_m * phi
    return np.minimum(np.maximum(z, -presliding_m), presliding_m)


def bouc_wen_slope(h: Array, direction: Array, yield_rad: Array) -> Array:
    """dh/dtheta of the normalised Bouc-Wen state (|h| <= 1; beta = gamma = 1/2, n = 2)."""
    same = (direction * h) > 0.0
    return np.where(same, 1.0 - h * h, 1.0) / yield_rad


def bouc_wen_update(h: Array, dtheta_rad: Array, yield_rad: Array) -> Array:
    """The state after a rotation ``dtheta_rad`` (midpoint rule, clipped to [-1, 1])."""
    direction = np.sign(dtheta_rad)
    mid = h + 0.5 * dtheta_rad * bouc_wen_slope(h, direction, yield_rad)
    return np.minimum(np.maximum(h + dtheta_rad * bouc_wen_slope(mid, direction, yield_rad),
                                 -1.0), 1.0)
