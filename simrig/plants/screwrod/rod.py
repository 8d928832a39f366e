"""The bending section as a Kirchhoff rod pressed against a compliant wall.

A tendon at constant offset ``r`` from the axis, fixed at the tip, loads the rod with a uniform
moment ``T r`` (its distributed lumen forces and its end force together), so a free section
bends at constant curvature. Once the tip reaches the wall (a plane parallel to the section's
base axis at ``gap``), the wall pushes back with ``F = k (y_tip - gap)`` and the moment along the
rod becomes ``T r - F (x_tip - x(s))``: curvature is no longer constant and the shape is a
boundary-value problem. It is solved once per plant build by shooting on ``F`` (bisection on the
wall's force balance, fixed-point on the rod's geometry) over a grid of tendon moments, giving a
monotone table of the tendon moment needed for each tip angle.
"""

from __future__ import annotations

import bisect
import math

import numpy as np

_NODES = 40
_GRID = 160
_GEOMETRY_PASSES = 12
_BISECTIONS = 36


def wall_table(length_m: float, stiffness_Nm_per_rad: float, gap_m: float,
               wall_N_per_m: float, max_tip_rad: float = 3.0
               ) -> tuple[list[float], list[float]]:
    """Tip angles (rad) and the tendon moments (N m) that hold them, tip against the wall.

    Starts at the tip angle where the free arc first touches the wall; below it the rod is free
    (moment = stiffness x angle)."""
    ei = stiffness_Nm_per_rad * length_m
    ds = length_m / _NODES
    s = (np.arange(_NODES) + 0.5) * ds
    touch = _touch_angle(length_m, gap_m)
    m_touch = stiffness_Nm_per_rad * touch
    moments = m_touch + np.linspace(0.0, 1.0, _GRID) ** 1.5 * (
        stiffness_Nm_per_rad * max_tip_rad * 4.0)
    lo = np.zeros(_GRID)
    hi = moments / (0.05 * length_m)  # a wall force that would straighten the rod outright
    for _ in range(_BISECTIONS):
        f = 0.5 * (lo + hi)
        y_tip = _shape(moments, f, ei, s, ds)[1]
        pushes_harder = f / wall_N_per_m > y_tip - gap_m  # wall force above its indentation
        hi = np.where(pushes_harder, f, hi)
        lo = np.where(pushes_harder, lo, f)
    tip, _ = _shape(moments, 0.5 * (lo + hi), ei, s, ds)
    keep = tip <= max_tip_rad
    theta = [touch] + [float(t) for t in tip[keep][1:]]
    moment = [m_touch] + [float(m) for m in moments[keep][1:]]
    return _monotone(theta, moment)


def _touch_angle(length_m: float, gap_m: float) -> float:
    """Tip angle at which the free (constant-curvature) arc's tip reaches the wall."""
    lo, hi = 1e-6, 3.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if length_m * (1.0 - np.cos(mid)) / mid < gap_m:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _shape(moments: np.ndarray, forces: np.ndarray, ei: float, s: np.ndarray, ds: float
           ) -> tuple[np.ndarray, np.ndarray]:
    """(tip angle, tip lateral offset) per grid row under tendon moment and wall force."""
    x = np.broadcast_to(s, (moments.size, s.size)).copy()
    for _ in range(_GEOMETRY_PASSES):
        x_tip = x[:, -1:] + 0.5 * ds
        kappa = (moments[:, None] - forces[:, None] * (x_tip - x)) / ei
        angle = np.cumsum(kappa, axis=1) * ds - 0.5 * kappa * ds
        x = np.cumsum(np.cos(angle), axis=1) * ds - 0.5 * np.cos(angle) * ds
    y = np.sum(np.sin(angle), axis=1) * ds
    return np.sum(kappa, axis=1) * ds, y


def _monotone(theta: list[float], moment: list[float]) -> tuple[list[float], list[float]]:
    """Drop grid rows that do not advance the tip (the table must be invertible)."""
    t_out, m_out = [theta[0]], [moment[0]]
    for t, m in zip(theta[1:], moment[1:], strict=True):
        if t > t_out[-1] + 1e-9 and m > m_out[-1]:
            t_out.append(t)
            m_out.append(m)
    return t_out, m_out


class BendingSection:
    """Tendon moment (N m) and its slope for a tip angle (rad), in one bending plane."""

    def __init__(self, length_m: float, stiffness_Nm_per_rad: float, limit_rad: float,
                 link_Nm_per_rad: float, gap_m: float | None = None,
                 wall_N_per_m: float = 0.0) -> None:
        self.k = stiffness_Nm_per_rad
        self.limit_rad = limit_rad
        self.k_link = link_Nm_per_rad
        self._theta: list[float] = []
        self._moment: list[float] = []
        if gap_m is not None and wall_N_per_m > 0.0:
            self._theta, self._moment = wall_table(length_m, stiffness_Nm_per_rad, gap_m,
                                                   wall_N_per_m)
        self.touch_rad = self._theta[0] if self._theta else float("inf")

    def moment(self, theta_rad: float) -> tuple[float, float]:
        """(moment, d moment / d angle): the open section (and the wall), plus the closed
        links' rim contact beyond the bend limit either way."""
        m, k = self._open(theta_rad)
        over = abs(theta_rad) - self.limit_rad
        if over > 0.0:
            m += math.copysign(self.k_link * over, theta_rad)
            k += self.k_link
        return m, k

    def _open(self, theta_rad: float) -> tuple[float, float]:
        """The open section's moment and slope; linear beyond the wall table's last row."""
        if theta_rad <= self.touch_rad:
            return self.k * theta_rad, self.k
        t, m = self._theta, self._moment
        i = bisect.bisect_right(t, theta_rad) - 1
        if i >= len(t) - 1:
            i = len(t) - 2
        slope = (m[i + 1] - m[i]) / (t[i + 1] - t[i])
        return m[i] + slope * (theta_rad - t[i]), slope
