"""Quasi-static equilibrium of one tendon in a sheath with distributed Coulomb friction.

The tendon runs through ``N`` sheath elements. Element ``j`` carries tension ``T[j]``; the friction
at the node in front of it (capstan law, normal force = tension x wrap angle) limits the tension
change there to a factor ``g[j] = exp(-mu_j * dphi_j)``. When the proximal end is pulled, a slip
front travels distally: slipping elements follow ``T[j] = T_p * G[j]`` (``G`` = cumulative product
of ``g``), elements beyond the front stick and keep their old tension (and position). Releasing
is the mirror image with ``T[j] = T_p / G[j]``. A tension-independent drag ``h[j]`` per element
(sheath preload, tendon bending stiffness in the lumen) makes the profile affine,
``T[j] = T_p * G[j] - H[j]``. If the front reaches the distal end, the
bending section moves: it is a chain of ``M`` joints, each a rotational spring ``K_i`` with a
Coulomb friction moment ``M_i``, all loaded by the moment ``r_b * (T_d - T_other)``.

Displacement compatibility (proximal pull = free-segment stretch + sheath stretch + distal
travel) is a monotone piecewise-linear function of the proximal tension ``T_p`` whose
breakpoints are the slip thresholds, so the equilibrium is found exactly with a handful of
vectorised numpy operations (no iteration). Releasing is solved as pulling in a mirrored frame
(``T -> -T``, ``G -> 1/G``, joint angles and the target negated), which keeps one code path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


@dataclass
class TendonGeometry:
    """Per-tendon constants of the solve (SI units)."""

    free_compliance_m_per_N: float
    """Compliance of the tendon between pulley and sheath entry (no friction there)."""
    element_compliance_m_per_N: FloatArray
    """Compliance of each sheath element, shape (N,)."""
    offset_m: float
    """Tendon offset from the neutral axis in the bending section (moment arm ``r_b``)."""
    joint_stiffness_Nm_per_rad: FloatArray
    """Rotational stiffness of each bending joint, shape (M,)."""
    joint_friction_Nm: FloatArray
    """Coulomb friction moment of each bending joint, shape (M,)."""


def residual_m(
    geom: TendonGeometry,
    tension_N: FloatArray,
    proximal_N: float,
    joints_rad: FloatArray,
    target_m: float,
) -> float:
    """Compatibility residual of a state: stretch + distal travel - proximal pull (metres).

    Positive means the tendon is longer than the pulley allows (it must release), negative means
    the pulley has drawn in more than the tendon accounts for (it must pull).
    """
    stretch = proximal_N * geom.free_compliance_m_per_N + float(
        tension_N @ geom.element_compliance_m_per_N
    )
    return stretch + geom.offset_m * float(joints_rad.sum()) - target_m


def solve_pull(
    geom: TendonGeometry,
    gain: FloatArray,
    drag_N: FloatArray,
    tension_N: FloatArray,
    joints_rad: FloatArray,
    other_distal_N: float,
    target_m: float,
) -> tuple[float, FloatArray, FloatArray]:
    """Equilibrium after the proximal end moved by a pull (or a mirrored release).

    ``gain`` is the cumulative friction factor ``G`` (pull) or ``1/G`` (mirrored release) and
    ``drag_N`` the accumulated tension-independent drag ``H`` (a slipping element carries
    ``T_p * G - H``); ``tension_N``, ``joints_rad``, ``other_distal_N`` and ``target_m`` are in
    the same frame.
    Returns the proximal tension and the new tension profile and joint angles (not clamped: the
    caller applies the tendon-cannot-push limit).
    """
    n = tension_N.shape[0]
    m = joints_rad.shape[0]
    ck = geom.element_compliance_m_per_N
    rb = geom.offset_m
    g_end = float(gain[-1])

    # Slip thresholds of the elements in terms of the proximal tension; physically the front
    # advances from the proximal end, hence the running maximum.
    elem_bp = np.maximum.accumulate((tension_N + drag_N) / gain)
    # Joint i starts to turn when the distal tension exceeds its friction band.
    k = geom.joint_stiffness_Nm_per_rad
    mf = geom.joint_friction_Nm
    joint_td = (k * joints_rad + mf) / rb + other_distal_N
    order = np.argsort(joint_td)
    inv_k = 1.0 / k[order]
    h_end = float(drag_N[-1])
    joint_bp = np.maximum((joint_td[order] + h_end) / g_end, elem_bp[-1])

    # Slope of the residual with the first s elements slipping, s = 0..N.
    slope_e = np.empty(n + 1)
    slope_e[0] = geom.free_compliance_m_per_N
    np.cumsum(gain * ck, out=slope_e[1:])
    slope_e[1:] += geom.free_compliance_m_per_N
    drag_e = np.zeros(n + 1)
    np.cumsum(drag_N * ck, out=drag_e[1:])
    # Stretch of the elements that still stick (from element s on).
    stuck = np.zeros(n + 1)
    stuck[:n] = np.cumsum((tension_N * ck)[::-1])[::-1]
    x_d = rb * float(joints_rad.sum())

    f_e = elem_bp * slope_e[:n] - drag_e[:n] + stuck[:n] + x_d - target_m

    a1 = np.zeros(m + 1)
    np.cumsum(inv_k, out=a1[1:])
    a2 = np.zeros(m + 1)
    np.cumsum(mf[order] * inv_k, out=a2[1:])
    a3 = np.zeros(m + 1)
    a3[:m] = np.cumsum(joints_rad[order][::-1])[::-1]
    td = joint_bp * g_end - h_end
    xd_j = rb * ((rb * (td - other_distal_N)) * a1[:m] - a2[:m] + a3[:m])
    f_j = joint_bp * slope_e[n] - drag_e[n] + xd_j - target_m

    slope_j = slope_e[n] + rb * rb * g_end * a1
    bp = np.concatenate((elem_bp, joint_bp))
    f = np.concatenate((f_e, f_j))
    idx = int(np.count_nonzero(f < 0.0))
    if idx < n:
        t_p = float(bp[idx] - f[idx] / slope_e[idx])
    elif idx < n + m:
        t_p = float(bp[idx] - f[idx] / slope_j[idx - n])
    else:
        t_p = float(bp[-1] - f[-1] / slope_j[m])
    new_t, new_j = apply_pull(
        geom, gain, drag_N, tension_N, joints_rad, other_distal_N, t_p, elem_bp
    )
    return t_p, new_t, new_j


def apply_pull(
    geom: TendonGeometry,
    gain: FloatArray,
    drag_N: FloatArray,
    tension_N: FloatArray,
    joints_rad: FloatArray,
    other_distal_N: float,
    proximal_N: float,
    elem_bp: FloatArray | None = None,
) -> tuple[FloatArray, FloatArray]:
    """New tension profile and joint angles for a given proximal tension (pull frame)."""
    if elem_bp is None:
        elem_bp = np.maximum.accumulate((tension_N + drag_N) / gain)
    new_t = np.where(proximal_N > elem_bp, proximal_N * gain - drag_N, tension_N)
    td = float(new_t[-1])
    k = geom.joint_stiffness_Nm_per_rad
    moved = (geom.offset_m * (td - other_distal_N) - geom.joint_friction_Nm) / k
    new_j = np.maximum(joints_rad, moved)
    return new_t, new_j
