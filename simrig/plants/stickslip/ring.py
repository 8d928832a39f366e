"""One knob as a ring of nodes: drum, + tendon's sheath nodes, tip, - tendon's sheath nodes.

Coordinates (metres, all along the tendons): node 0 is the drum's draw ``r psi``; nodes 1..N the
pulling tendon's sheath nodes from proximal to distal (pulled-in displacement); node N+1 the tip's
draw ``d theta``; nodes N+2..2N+1 the antagonist's nodes from distal to proximal (its paid-out
displacement, so that every segment's stretch is left node minus right node). Segment k joins
node k-1 and node k (segment 0 joins the antagonist's proximal node back to the drum).

Each step is quasi-static (the tendons' and tip's own dynamics are kHz, far above the drive's
30 Hz): stuck nodes stay where they were, sliding nodes carry their kinetic friction, the rest is
in equilibrium. Which nodes slide is found by an active set (Karnopp: a stuck node breaks loose
past its static friction, a sliding node sticks when it would reverse); each active set is solved
by Newton on a cyclic tridiagonal matrix (pure Python: ~20 unknowns).
"""

from __future__ import annotations

import math

from simrig.plants.stickslip.laws import prony_factors, tip_moment
from simrig.plants.stickslip.params import (
    GRAVITY_M_S2,
    NODES_PER_TENDON,
    REGULARISATION,
    TIP_LINKS,
    StickSlipKnobParams,
    StickSlipParamError,
)

_TOL_N = 1e-7
"""Force balance met to 0.1 mN (tensions are 1-30 N)."""
_MAX_NEWTON = 40
_MAX_PASSES = 60
_MAX_MOVE_M = 5e-4
"""Newton step limit: keeps an iterate from jumping across a slack edge in one go."""


class KnobRing:
    """One knob's drum, cable drive, tendon pair and bending plane."""

    def __init__(self, p: StickSlipKnobParams, curvature_deg: float = 0.0) -> None:
        p.check()
        self.p = p
        n = NODES_PER_TENDON
        self.n_nodes = 2 * n + 2
        self.tip = n + 1
        self.r_m = p.pulley_radius_mm * 1e-3
        self.d_m = p.tendon_offset_mm * 1e-3
        element_m = p.sheath_length_m / n
        tip_m = p.tip_length_mm * 1e-3
        lengths = [element_m] * self.n_nodes
        lengths[1] = p.free_length_pos_m + 0.5 * element_m
        lengths[0] = p.free_length_neg_m + 0.5 * element_m
        lengths[n + 1] = 0.5 * element_m + tip_m
        lengths[n + 2] = 0.5 * element_m + tip_m
        self.length_m = lengths
        self.toe_m = [0.0] * self.n_nodes
        self.toe_m[1] = self.toe_m[0] = p.toe_mm * 1e-3
        self.slack_delta_m = (0.0, 0.0)
        self._segment_constants()
        self.drag_N = [p.sheath_drag_N / n] * self.n_nodes
        self.drag_N[0] = p.handle_friction_Nm / self.r_m
        self.drag_N[self.tip] = 0.0
        self.drive_N_per_m = p.drive_stiffness_Nm_per_rad / (self.r_m * self.r_m)
        self.set_curvature(curvature_deg)
        self.reset()

    def set_curvature(self, curvature_deg: float) -> None:
        """Sheath laid in a bend: every sheath node's wrap grows by its share of it."""
        if not (math.isfinite(curvature_deg) and curvature_deg >= 0.0):
            raise StickSlipParamError(
                f"sheath_curvature_deg must be finite and >= 0, got {curvature_deg!r}")
        per_node = math.radians(self.p.sheath_wrap_deg + curvature_deg) / NODES_PER_TENDON
        self.base_wrap_rad = [per_node] * self.n_nodes
        self.base_wrap_rad[0] = 0.0
        self.base_wrap_rad[self.tip] = 0.0

    def set_slack_delta(self, pos_mm: float, neg_mm: float) -> None:
        """Tendons lengthened (+) or shortened at the crimps since assembly."""
        self.slack_delta_m = (pos_mm * 1e-3, neg_mm * 1e-3)
        self._segment_constants()

    def reset(self) -> None:
        m = self.n_nodes
        self.y = [0.0] * m
        self.state = [0] * m  # -1/+1 sliding that way, 0 stuck
        self.eps = [0.0] * m
        self.q1 = [0.0] * m
        self.q2 = [0.0] * m
        self.bend_rad = 0.0
        self.torque_Nm = 0.0

    # -- one segment ------------------------------------------------------------------------
    def _segment_constants(self) -> None:
        """Per segment: slack (only at the drum crimps), 1/length, the numerical regulariser."""
        p = self.p
        slack = [0.0] * self.n_nodes
        slack[1] = p.slack_pos_mm * 1e-3 + self.slack_delta_m[0]
        slack[0] = p.slack_neg_mm * 1e-3 + self.slack_delta_m[1]
        self._slack_m = slack
        self._inv_length = [1.0 / length for length in self.length_m]
        self._reg = [REGULARISATION * p.tendon_stiffness_N / length for length in self.length_m]

    def _tensions(self, y: list[float], f1: tuple[float, float], f2: tuple[float, float]
                  ) -> tuple[list[float], list[float], list[float]]:
        """Tension, its slope in the segment's stretch, and the load-carrying strain.

        A braid past its slack straightens over its toe before it stretches linearly: the
        load-carrying stretch is quadratic over the toe, then linear, continuous in value and
        slope (a smooth dead-zone edge). Its strain drives the long-term stiffness and the two
        Maxwell branches; a tendon carries no compression.
        """
        p = self.p
        ea0 = p.tendon_stiffness_N
        ea1 = ea0 * p.creep_fast_share * f1[1]
        ea2 = ea0 * p.creep_slow_share * f2[1]
        gain = ea0 + ea1 + ea2
        a1, a2 = f1[0], f2[0]
        m = self.n_nodes
        t = [0.0] * m
        dt = [0.0] * m
        eps = [0.0] * m
        slack, toe, inv_len, reg = self._slack_m, self.toe_m, self._inv_length, self._reg
        eps_old, q1, q2 = self.eps, self.q1, self.q2
        for k in range(m):
            e = y[k - 1] - y[k]
            x = e - slack[k]
            if x <= 0.0:
                t[k] = reg[k] * e
                dt[k] = reg[k]
                continue
            tk = toe[k]
            if x < tk:
                g, dg = 0.5 * x * x / tk, x / tk
            else:
                g, dg = x - 0.5 * tk, 1.0
            ek = g * inv_len[k]
            eps[k] = ek
            de = ek - eps_old[k]
            tension = ea0 * ek + a1 * q1[k] + a2 * q2[k] + (ea1 + ea2) * de
            if tension > 0.0:
                t[k] = tension + reg[k] * e
                dt[k] = gain * dg * inv_len[k] + reg[k]
            else:
                t[k] = reg[k] * e
                dt[k] = reg[k]
        return t, dt, eps

    # -- the step ---------------------------------------------------------------------------
    def step(self, dt_s: float, knob_rad: float, other_bend_rad: float) -> None:
        """Advance to the drive shaft at ``knob_rad``; tip and torque in ``bend_rad``,
        ``torque_Nm``."""
        p = self.p
        f1 = prony_factors(dt_s, p.creep_fast_time_s)
        f2 = prony_factors(dt_s, p.creep_slow_time_s)
        bend = math.hypot(self.bend_rad, other_bend_rad)
        wrap = list(self.base_wrap_rad)
        n = NODES_PER_TENDON
        wrap[n] += bend  # the tendon rubs round the bent section at the shaft's end
        wrap[n + 2] += bend
        y_prev = list(self.y)
        y = list(self.y)
        state = self.state
        drive_x_m = self.r_m * knob_rad
        for _ in range(_MAX_PASSES):
            for k in range(self.n_nodes):
                if state[k] == 0 and k != self.tip:
                    y[k] = y_prev[k]
            y, t, eps = self._newton(y, state, wrap, drive_x_m, f1, f2)
            if not self._update_states(y, y_prev, state, wrap, drive_x_m, t):
                break
        for k in range(self.n_nodes):
            de = eps[k] - self.eps[k]
            self.q1[k] = f1[0] * self.q1[k] + p.tendon_stiffness_N * p.creep_fast_share * f1[1] * de
            self.q2[k] = f2[0] * self.q2[k] + p.tendon_stiffness_N * p.creep_slow_share * f2[1] * de
        self.eps = eps
        self.y = y
        self.bend_rad = y[self.tip] / self.d_m
        self.torque_Nm = p.drive_stiffness_Nm_per_rad * (knob_rad - y[0] / self.r_m)

    def _forces(self, y: list[float], state: list[int], wrap: list[float], drive_x_m: float,
                f1: tuple[float, float], f2: tuple[float, float]) -> tuple[
                    list[float], list[float], list[float], list[float], list[float], list[float]]:
        """Residual (net force on every node with the present states) and its Jacobian bands
        (coefficient of the node before, of the node, of the node after), plus tensions and
        strains."""
        p = self.p
        m = self.n_nodes
        t, dt, eps = self._tensions(y, f1, f2)
        res = [0.0] * m
        lo = [0.0] * m
        di = [0.0] * m
        up = [0.0] * m
        mu = p.sheath_friction
        for k in range(m):
            kn = k + 1 if k + 1 < m else 0
            tl, tr, dl, dr = t[k], t[kn], dt[k], dt[kn]
            r = tl - tr
            a, b, c = dl, -dl - dr, dr
            if k == 0:
                r += self.drive_N_per_m * (drive_x_m - y[0])
                b -= self.drive_N_per_m
            elif k == self.tip:
                mt, kt = tip_moment(y[k] / self.d_m, p.bend_stiffness_Nm_per_rad,
                                    p.bend_stiffening_per_rad2, TIP_LINKS, p.tip_mass_g * 1e-3,
                                    p.tip_length_mm * 1e-3, GRAVITY_M_S2)
                r -= mt / self.d_m
                b -= kt / (self.d_m * self.d_m)
            sig = state[k]
            if sig != 0:
                h = sig * mu * wrap[k] * 0.5
                r -= h * (tl + tr) + sig * self.drag_N[k]
                a -= h * dl
                b -= h * (dr - dl)
                c += h * dr
            elif k != self.tip:
                r, a, b, c = 0.0, 0.0, 1.0, 0.0
            res[k], lo[k], di[k], up[k] = r, a, b, c
        return res, lo, di, up, t, eps

    def _newton(self, y: list[float], state: list[int], wrap: list[float], drive_x_m: float,
                f1: tuple[float, float], f2: tuple[float, float]
                ) -> tuple[list[float], list[float], list[float]]:
        """Equilibrium of the free nodes; the tensions and strains of its last evaluation."""
        for _ in range(_MAX_NEWTON):
            res, lo, di, up, t, eps = self._forces(y, state, wrap, drive_x_m, f1, f2)
            if max(abs(r) for r in res) < _TOL_N:
                break
            dy = _solve_ring(lo, di, up, [-r for r in res])
            big = max(abs(d) for d in dy)
            scale = _MAX_MOVE_M / big if big > _MAX_MOVE_M else 1.0
            y = [yi + scale * d for yi, d in zip(y, dy, strict=True)]
            if big < 1e-15:
                break
        return y, t, eps

    def _update_states(self, y: list[float], y_prev: list[float], state: list[int],
                       wrap: list[float], drive_x_m: float, t: list[float]) -> bool:
        """Karnopp's switch on every contact (tensions ``t`` at ``y``); True if any changed."""
        mu_s = self.p.sheath_friction * self.p.stiction_ratio
        m = self.n_nodes
        changed = False
        for k in range(m):
            if k == self.tip:
                continue
            sig = state[k]
            if sig != 0:
                if (y[k] - y_prev[k]) * sig < 0.0:
                    state[k] = 0
                    changed = True
                continue
            kn = k + 1 if k + 1 < m else 0
            net = t[k] - t[kn]
            if k == 0:
                net += self.drive_N_per_m * (drive_x_m - y[0])
            ratio = self.p.brake_stiction_ratio if k == 0 else self.p.stiction_ratio
            cap = mu_s * wrap[k] * 0.5 * (t[k] + t[kn]) + ratio * self.drag_N[k]
            if abs(net) > cap:
                state[k] = 1 if net > 0.0 else -1
                changed = True
        return changed


def _solve_ring(lo: list[float], di: list[float], up: list[float], rhs: list[float]
                ) -> list[float]:
    """Solve the cyclic tridiagonal system (node 0 joins the last node): Thomas on nodes
    1..m-1 for the right-hand side and for node 0's column, then node 0 from its own row."""
    m = len(di)
    cp = [0.0] * m
    p = [0.0] * m
    w = [0.0] * m
    col_first, col_last = lo[1], up[m - 1]
    prev_c = 0.0
    prev_p = 0.0
    prev_w = 0.0
    for k in range(1, m):
        a = lo[k] if k > 1 else 0.0
        denom = di[k] - a * prev_c
        ck = up[k] / denom if k < m - 1 else 0.0
        colk = (col_first if k == 1 else 0.0) + (col_last if k == m - 1 else 0.0)
        p[k] = (rhs[k] - a * prev_p) / denom
        w[k] = (colk - a * prev_w) / denom
        cp[k] = ck
        prev_c, prev_p, prev_w = ck, p[k], w[k]
    for k in range(m - 2, 0, -1):
        p[k] -= cp[k] * p[k + 1]
        w[k] -= cp[k] * w[k + 1]
    denom0 = di[0] - up[0] * w[1] - lo[0] * w[m - 1]
    x0 = (rhs[0] - up[0] * p[1] - lo[0] * p[m - 1]) / denom0
    out = [0.0] * m
    out[0] = x0
    for k in range(1, m):
        out[k] = p[k] - x0 * w[k]
    return out
