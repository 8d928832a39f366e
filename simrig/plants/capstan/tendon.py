"""Quasi-static equilibrium of one tendon in a sheath with distributed Coulomb friction.

The tendon runs through ``N`` sheath elements. Element ``j`` carries tension ``T[j]``; the friction
at the node in front of it (capstan law, normal force = tension x wrap angle) limits the tension
change there to a factor ``g[j] = exp(-mu * dphi_j)``, plus a tension-independent drag ``h[j]``
(sheath preload, tendon bending stiffness in its lumen). When the proximal end is pulled, a slip
front travels distally: slipping elements follow ``T[j] = T_p * G[j] - H[j]`` (``G`` the
cumulative product of ``g``, ``H`` the accumulated drag), elements beyond the front stick and keep
their tension and position. Releasing is the mirror image (``T[j] = T_p / G[j] + H'[j]``). If the
front reaches the distal end, the bending section moves: a chain of ``M`` joints, each a
rotational spring ``K_i`` with a Coulomb friction moment ``M_i``, all loaded by the moment
``r_b * (T_d - T_other)``.

Displacement compatibility (pulley draw-in = free-segment stretch + sheath stretch + distal travel)
is a monotone piecewise-linear function of the proximal tension ``T_p`` whose breakpoints are the
slip thresholds, so the equilibrium is found exactly with a handful of vectorised numpy
operations, no iteration. Releasing is solved as pulling in a mirrored frame (``T -> -T``,
``G -> 1/G``, joint angles and target negated), which keeps one code path.
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


@dataclass
class PullSolution:
    """Equilibrium found by :func:`solve_pull` (pull frame)."""

    proximal_N: float
    tension_N: FloatArray
    joints_rad: FloatArray
    slope_m_per_N: float
    """d(residual)/d(T_p) at the solution; valid for the fast path only if ``all_slip``."""
    limit_N: float
    """Proximal tension at which the next slip threshold (a stuck joint) is reached."""
    all_slip: bool
    """The slip front reached the distal end (every element slides)."""


def residual_m(
    geom: TendonGeometry,
    tension_N: FloatArray,
    proximal_N: float,
    joints_rad: FloatArray,
    target_m: float,
) -> float:
    """Compatibility residual of a state: stretch + distal travel - pulley draw-in (metres).

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
    joint_friction_Nm: FloatArray,
    other_distal_N: float,
    target_m: float,
) -> PullSolution:
    """Equilibrium after the pulley moved by a pull (or a mirrored release).

    ``gain`` is ``G`` (pull) or ``1/G`` (mirrored release) and ``drag_N`` the matching ``H``;
    ``tension_N``, ``joints_rad``, ``other_distal_N`` and ``target_m`` are in the same frame.
    ``joint_friction_Nm`` is the friction each joint must overcome now (static or kinetic).
    The proximal tension is not clamped: the caller applies the tendon-cannot-push limit.
    """
    n = tension_N.shape[0]
    m = joints_rad.shape[0]
    ck = geom.element_compliance_m_per_N
    c0 = geom.free_compliance_m_per_N
    rb = geom.offset_m
    g_end = float(gain[-1])
    h_end = float(drag_N[-1])
    k = geom.joint_stiffness_Nm_per_rad

    # Slip thresholds of the elements in terms of the proximal tension; physically the front
    # advances from the proximal end, hence the running maximum.
    elem_bp = np.maximum.accumulate((tension_N + drag_N) / gain)
    # Joint i starts to turn when the distal tension leaves its friction band.
    joint_td = (k * joints_rad + joint_friction_Nm) / rb + other_distal_N
    order = np.argsort(joint_td)
    joint_bp = np.maximum((joint_td[order] + h_end) / g_end, elem_bp[-1])

    # Residual at every breakpoint. With s elements slipping the residual is
    # T_p * slope_e[s] - drag_e[s] + stuck[s] + x_d - target.
    slope_e = np.empty(n + 1)
    slope_e[0] = 0.0
    np.cumsum(gain * ck, out=slope_e[1:])
    slope_e += c0
    drag_e = np.zeros(n + 1)
    np.cumsum(drag_N * ck, out=drag_e[1:])
    stuck = np.zeros(n + 1)
    stuck[:n] = np.cumsum((tension_N * ck)[::-1])[::-1]
    x_d = rb * float(joints_rad.sum())

    # With every element slipping and the first q joints (in threshold order) turning:
    # x_d = rb * (rb * (T_d - T_o) * sum(1/K) - sum(M/K) + sum of the other joints' angles).
    inv_k = np.zeros(m + 1)
    np.cumsum(1.0 / k[order], out=inv_k[1:])
    mf_k = np.zeros(m + 1)
    np.cumsum(joint_friction_Nm[order] / k[order], out=mf_k[1:])
    rest = np.zeros(m + 1)
    rest[:m] = np.cumsum(joints_rad[order][::-1])[::-1]

    bp = np.concatenate((elem_bp, joint_bp))
    f = np.empty(n + m)
    f[:n] = elem_bp * slope_e[:n] - drag_e[:n] + stuck[:n] + x_d - target_m
    td = joint_bp * g_end - h_end
    f[n:] = (
        joint_bp * slope_e[n]
        - drag_e[n]
        + rb * (rb * (td - other_distal_N) * inv_k[:m] - mf_k[:m] + rest[:m])
        - target_m
    )
    slope = np.concatenate((slope_e[:n], slope_e[n] + rb * rb * g_end * inv_k))
    idx = int(np.count_nonzero(f < 0.0))
    if idx < n + m:
        t_p = float(bp[idx] - f[idx] / slope[idx])
        limit = float(bp[idx])
    else:
        t_p = float(bp[-1] - f[-1] / slope[-1])
        limit = float("inf")
    new_t, new_j = apply_pull(
        geom, gain, drag_N, tension_N, joints_rad, joint_friction_Nm, other_distal_N, t_p, elem_bp
    )
    return PullSolution(t_p, new_t, new_j, float(slope[min(idx, n + m)]), limit, idx >= n)


def apply_pull(
    geom: TendonGeometry,
    gain: FloatArray,
    drag_N: FloatArray,
    tension_N: FloatArray,
    joints_rad: FloatArray,
    joint_friction_Nm: FloatArray,
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
    turned = (geom.offset_m * (td - other_distal_N) - joint_friction_Nm) / k
    return new_t, np.maximum(joints_rad, turned)


def settle_breakaway(
    geom: TendonGeometry,
    gain: FloatArray,
    drag_N: FloatArray,
    joints_rad: FloatArray,
    freed: NDArray[np.bool_],
    kinetic_friction_Nm: FloatArray,
    other_distal_N: float,
    target_m: float,
) -> tuple[float, FloatArray, FloatArray]:
    """Equilibrium right after joints broke loose from static friction (pull frame).

    The whole tendon keeps sliding the same way, so its profile stays ``T_p * G - H``; the freed
    joints sit at their kinetic friction edge, the others stay put. The tendon takes up the
    slip: pulling, its tension drops (stick-slip); releasing, it rises again after the dip that
    broke the joints loose. One linear equation in ``T_p``.
    """
    ck = geom.element_compliance_m_per_N
    rb = geom.offset_m
    k = geom.joint_stiffness_Nm_per_rad
    g_end = float(gain[-1])
    h_end = float(drag_N[-1])
    s_n = geom.free_compliance_m_per_N + float((gain * ck).sum())
    hs_n = float((drag_N * ck).sum())
    inv_k_freed = float((1.0 / k[freed]).sum())
    mf_k_freed = float((kinetic_friction_Nm[freed] / k[freed]).sum())
    fixed = float(joints_rad[~freed].sum())
    # T_p*s_n - hs_n + rb*(fixed + rb*(T_p*g_end - h_end - T_o)*inv_k - mf_k) = target
    num = target_m + hs_n - rb * fixed - rb * (rb * (-h_end - other_distal_N) * inv_k_freed)
    num += rb * mf_k_freed
    t_p = num / (s_n + rb * rb * g_end * inv_k_freed)
    new_t = t_p * gain - drag_N
    td = float(new_t[-1])
    new_j = joints_rad.copy()
    new_j[freed] = (rb * (td - other_distal_N) - kinetic_friction_Nm[freed]) / k[freed]
    return t_p, new_t, new_j
