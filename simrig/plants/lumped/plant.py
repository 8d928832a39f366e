"""A tendon-sheath catheter as lumped contacts with Dahl friction, solved implicitly each step.

Per knob, a pulley draws in one tendon and pays out its antagonist. Each tendon runs

    pulley --free segment (slack + toe)--> handle guide --> sheath lumps 1..n --> bending section

Every contact (the handle guide, each sheath lump) is a Dahl friction element: its force follows
the tendon's travel exponentially over a presliding length towards a sliding level set by the
local tension (a lumped capstan, ``T_in (1 - exp(-mu psi))``) plus a constant drag. Tendon
segments are unilateral springs (a tendon cannot push); the free segment stiffens smoothly over
a toe region. The bending section is a spring with its own Dahl hysteresis. Each step takes the
Newton step of the quasi-static equilibrium (tangent stiffness: a tridiagonal chain per tendon,
coupled through the tip angle, solved by Thomas and a Schur complement) and integrates the Dahl
states exactly over it; a residual left by the nonlinearity is carried into the next step.
The knob torque is the pulley torque plus the knob's own Dahl friction.

Written independently of :mod:`simrig.plants.capstan`; only the :class:`~simrig.plant.Plant`
protocol is shared. Effects (all off by default) are in :class:`LumpedEffects`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.lumped.params import NOMINAL_KNOBS, LumpedEffects, LumpedKnobParams

_EPS_N_PER_M = 1.0
"""Tiny stiffness to ground on every node so a fully slack, friction-free node stays put."""
_SETTLED_M = 1e-12
"""Below this Newton move (m) with unchanged inputs the knob is at rest and is not re-solved."""
_SUBSTEP_OF_PRESLIDING = 0.25
_MAX_SUBSTEPS = 40
_TOE_FLOOR = 1e-3
"""Fraction of the segment stiffness kept as tangent of a slack segment (conditioning only)."""


class _Tendon:
    """One tendon: node draw-ins (m) and Dahl friction forces (N), proximal node first."""

    __slots__ = ("direction", "force_N", "k_seg", "u_m")

    def __init__(self, n_nodes: int, k_seg: float) -> None:
        self.k_seg = k_seg
        self.u_m = [0.0] * n_nodes
        self.force_N = [0.0] * n_nodes
        self.direction = [0.0] * n_nodes


class _Knob:
    """The two tendons of one knob, their bending section and the knob's own friction."""

    def __init__(self, p: LumpedKnobParams, eff: LumpedEffects, n_lumps: int) -> None:
        self.p = p
        self.eff = eff
        n = n_lumps + 1  # handle guide + sheath lumps
        self.n = n
        ea = p.tendon_stiffness_N / (1.0 + eff.tendon_compliance)
        self.k_free = ea / p.free_length_m
        self.k_seg = ea * (n_lumps + 1) / p.sheath_length_m
        self.toe_m = p.toe_mm * 1e-3
        self.radius_m = p.pulley_radius_mm * 1e-3
        self.arm_m = p.tendon_offset_mm * 1e-3
        self.n_lumps = n_lumps
        self.slack_delta_m = (0.0, 0.0)
        self._settled: tuple[float, float, float] | None = None
        self._shape(eff)
        self.drag_N = [0.0] + [p.sheath_drag_N / n_lumps] * n_lumps
        self.delta_m = p.presliding_mm * 1e-3
        self.viscous = [0.0] + [eff.viscous_N_s_per_m] * n_lumps
        self.has_viscosity = eff.viscous_N_s_per_m > 0.0
        self._no_viscosity = [0.0] * n
        self.bend_delta_rad = math.radians(p.bend_presliding_deg)
        self.handle_delta_deg = p.handle_presliding_deg
        self.reset()

    def _shape(self, eff: LumpedEffects) -> None:
        """Wrap of each contact and the path shortening from the sheath's bend."""
        p, n_lumps = self.p, self.n_lumps
        # Lumped capstan per contact: the share of incoming tension a sliding contact takes.
        wraps = [math.radians(p.guide_wrap_deg) * p.guide_friction]
        curve = math.radians(eff.sheath_curvature_deg)
        for j in range(n_lumps):
            extra = curve / math.ceil(n_lumps / 2) if j >= n_lumps // 2 else 0.0
            wraps.append((math.radians(p.sheath_wrap_deg) / n_lumps + extra) * p.sheath_friction)
        self.take = [1.0 - math.exp(-w) for w in wraps]
        self.curve_slack_m = eff.lumen_clearance_mm * 1e-3 * curve

    def reshape(self, eff: LumpedEffects, slack_delta_mm: tuple[float, float]) -> None:
        """A new sheath shape mid-run: the distal lumps' wrap, the path length and each
        tendon's slack change; node positions and Dahl forces carry over (the forces are
        clipped to the new sliding levels at the next move)."""
        self.eff = eff
        self._shape(eff)
        self.slack_delta_m = (slack_delta_mm[0] * 1e-3, slack_delta_mm[1] * 1e-3)
        self._settled = None  # the equilibrium belongs to the old shape

    def reset(self) -> None:
        self.tendons = (_Tendon(self.n, self.k_seg), _Tendon(self.n, self.k_seg))
        self.tip_rad = 0.0
        self.bend_force_Nm = 0.0
        self.bend_dir = 0.0
        self.handle_Nm = 0.0
        self.knob_deg: float | None = None
        self.creep_m = [0.0, 0.0]
        self.proximal_N = [0.0, 0.0]
        self._settled = None
        self._pulley: list[float] | None = None

    # -- constitutive laws -----------------------------------------------------------------
    def _free(self, stretch_m: float) -> tuple[float, float]:
        """Tension and tangent of the free segment: zero, then a quadratic toe, then linear."""
        k, toe = self.k_free, self.toe_m
        if stretch_m <= 0.0:
            return 0.0, k * _TOE_FLOOR
        if stretch_m < toe:
            return 0.5 * k * stretch_m * stretch_m / toe, max(k * stretch_m / toe, k * _TOE_FLOOR)
        return k * (stretch_m - 0.5 * toe), k

    # -- one step --------------------------------------------------------------------------
    def step(self, dt_s: float, knob_deg: float, other_tip_rad: float,
             other_tension_N: float) -> tuple[float, float]:
        """Advance to ``knob_deg``; returns (tip angle rad, knob torque Nm)."""
        p, eff = self.p, self.eff
        prev = knob_deg if self.knob_deg is None else self.knob_deg
        self.knob_deg = knob_deg
        draw = self.radius_m * math.radians(knob_deg)
        slack = [p.slack_pos_mm * 1e-3 + self.slack_delta_m[0],
                 p.slack_neg_mm * 1e-3 + self.slack_delta_m[1]]
        bend_friction = p.bend_friction_Nm
        if eff.coupling > 0.0:
            squeeze = eff.coupling_compression_mm_per_N * 1e-3 * other_tension_N
            shift = self.arm_m * math.sin(math.radians(eff.coupling_lumen_angle_deg)) * (
                other_tip_rad)
            slack = [slack[0] + eff.coupling * (squeeze - shift),
                     slack[1] + eff.coupling * (squeeze + shift)]
            bend_friction *= 1.0 + eff.coupling * eff.coupling_friction_per_rad * abs(
                other_tip_rad)
        pulley = [draw - slack[0] - self.curve_slack_m - self.creep_m[0],
                  -draw - slack[1] - self.curve_slack_m - self.creep_m[1]]
        key = (pulley[0], pulley[1], bend_friction)
        if key != self._settled:  # at rest and converged, nothing would move: skip the solve
            # Sub-steps keep each Newton step's travel within a fraction of the presliding
            # length (the Dahl law's scale), so the result does not depend on the knob speed.
            start = self._pulley or pulley
            travel = max(abs(pulley[0] - start[0]), abs(pulley[1] - start[1]))
            n_sub = min(max(math.ceil(travel / (_SUBSTEP_OF_PRESLIDING * self.delta_m)), 1),
                        _MAX_SUBSTEPS)
            visc = self._no_viscosity
            if self.has_viscosity and dt_s > 0.0:
                visc = [v * n_sub / dt_s for v in self.viscous]
            if n_sub == 1:
                moved = self._solve(pulley, visc, bend_friction)
            else:
                for i in range(1, n_sub + 1):
                    w = i / n_sub
                    at = [a + w * (b - a) for a, b in zip(start, pulley, strict=True)]
                    moved = self._solve(at, visc, bend_friction)
            self._settled = key if moved < _SETTLED_M else None
        self._pulley = pulley
        if eff.creep_compliance_mm_per_N > 0.0 and dt_s > 0.0:
            a = -math.expm1(-dt_s / eff.creep_time_s)
            for s in (0, 1):
                target = eff.creep_compliance_mm_per_N * 1e-3 * self.proximal_N[s]
                self.creep_m[s] += a * (target - self.creep_m[s])
        step = knob_deg - prev
        if step != 0.0:
            level = p.handle_friction_Nm if step > 0.0 else -p.handle_friction_Nm
            self.handle_Nm = level + (self.handle_Nm - level) * math.exp(
                -abs(step) / self.handle_delta_deg)
        torque = self.radius_m * (self.proximal_N[0] - self.proximal_N[1]) + self.handle_Nm
        return self.tip_rad, torque

    def _solve(self, pulley: list[float], visc: list[float], bend_friction: float) -> float:
        """One Newton step of the equilibrium, re-taken once if a contact turned the other way;
        returns the largest node or tip-arc move (m)."""
        dirs = [self.tendons[0].direction, self.tendons[1].direction]
        bend_dir = self.bend_dir
        du, dtheta = self._newton(pulley, visc, bend_friction, dirs, bend_dir)
        turned = _turned(du, dirs) or (dtheta * bend_dir < 0.0 or (dtheta and not bend_dir))
        if turned:
            dirs = [[_sign(d, old) for d, old in zip(row, old_row, strict=True)]
                    for row, old_row in zip(du, dirs, strict=True)]
            bend_dir = _sign(dtheta, bend_dir)
            du, dtheta = self._newton(pulley, visc, bend_friction, dirs, bend_dir)
        return self._apply(du, dtheta, pulley, bend_friction)

    def _newton(self, pulley: list[float], visc: list[float], bend_friction: float,
                dirs: list[list[float]], bend_dir: float
                ) -> tuple[list[list[float]], float]:
        """Assemble and solve the tangent system in one pass per tendon (Thomas forward sweep),
        eliminate the tip angle (Schur complement), then back-substitute once per tendon."""
        n = self.n
        arm = self.arm_m
        tip_arc = arm * self.tip_rad
        take, drag, inv_delta = self.take, self.drag_N, 1.0 / self.delta_m
        k_free, toe = self.k_free, self.toe_m
        sweeps = []
        last_k = [0.0, 0.0]
        tip_load = 0.0
        for s in (0, 1):
            t = self.tendons[s]
            sign = 1.0 if s == 0 else -1.0
            u, force, d_s, k = t.u_m, t.force_N, dirs[s], t.k_seg
            e = pulley[s] - u[0]
            if e <= 0.0:
                t_in, k_in = 0.0, k_free * _TOE_FLOOR
            elif e < toe:
                t_in, k_in = 0.5 * k_free * e * e / toe, max(k_free * e / toe, k_free * _TOE_FLOOR)
            else:
                t_in, k_in = k_free * (e - 0.5 * toe), k_free
            c = [0.0] * n
            xp = [0.0] * n
            yp = [0.0] * n
            c_prev = x_prev = y_prev = 0.0
            t_out = k_out = 0.0
            for j in range(n):
                stretch = u[j] - (u[j + 1] if j + 1 < n else sign * tip_arc)
                if stretch > 0.0:
                    t_out, k_out = k * stretch, k
                else:
                    t_out, k_out = 0.0, k * _TOE_FLOOR
                f = force[j]
                # Dahl tangent (F_c - d F)/delta: stiff right after a reversal, ~0 when sliding.
                dahl = (t_in * take[j] + drag[j] - d_s[j] * f) * inv_delta
                diag = k_in + k_out + dahl + visc[j] + _EPS_N_PER_M
                load = -sign * arm * k_out if j == n - 1 else 0.0
                if j:
                    diag += k_in * c_prev
                    x_prev = (t_in - t_out - f + k_in * x_prev) / diag
                    y_prev = (load + k_in * y_prev) / diag
                else:
                    x_prev = (t_in - t_out - f) / diag
                    y_prev = load / diag
                c_prev = -k_out / diag
                c[j], xp[j], yp[j] = c_prev, x_prev, y_prev
                t_in, k_in = t_out, k_out
            sweeps.append((c, xp, yp))
            last_k[s] = k_out
            tip_load += sign * t_out
        k_b = self.p.bend_stiffness_Nm_per_rad
        f_b = self.bend_force_Nm
        dahl_b = (bend_friction - bend_dir * f_b) / self.bend_delta_rad
        b0, b1 = -arm * last_k[0], arm * last_k[1]
        (_, x0, y0), (_, x1, y1) = sweeps
        num = arm * tip_load - k_b * self.tip_rad - f_b - b0 * x0[-1] - b1 * x1[-1]
        den = arm * arm * (last_k[0] + last_k[1]) + k_b + dahl_b - b0 * y0[-1] - b1 * y1[-1]
        dtheta = num / den
        du = []
        for c, xp, yp in sweeps:
            z = [xi - yi * dtheta for xi, yi in zip(xp, yp, strict=True)]
            for j in range(n - 2, -1, -1):
                z[j] -= c[j] * z[j + 1]
            du.append(z)
        return du, dtheta

    def _apply(self, du: list[list[float]], dtheta: float, pulley: list[float],
               bend_friction: float) -> float:
        """Move the nodes and the tip, integrate every Dahl state exactly over the move and
        remember each contact's direction; returns the largest node or tip-arc move (m)."""
        self.tip_rad += dtheta
        self.bend_force_Nm = _dahl(self.bend_force_Nm, dtheta, bend_friction, self.bend_delta_rad)
        self.bend_dir = _sign(dtheta, self.bend_dir)
        largest = abs(dtheta) * self.arm_m
        n, take, drag, delta = self.n, self.take, self.drag_N, self.delta_m
        for s, t in enumerate(self.tendons):
            moves = du[s]
            u = t.u_m = [u + d for u, d in zip(t.u_m, moves, strict=True)]
            t_in = self._free(pulley[s] - u[0])[0]
            self.proximal_N[s] = t_in
            forces, direction, k = t.force_N, list(t.direction), t.k_seg
            for j in range(n):
                d = moves[j]
                cap = t_in * take[j] + drag[j]
                f = forces[j]
                if d > 0.0:
                    f = cap + (f - cap) * math.exp(-d / delta)
                    direction[j] = 1.0
                    largest = max(largest, d)
                elif d < 0.0:
                    f = -cap + (f + cap) * math.exp(d / delta)
                    direction[j] = -1.0
                    largest = max(largest, -d)
                forces[j] = cap if f > cap else -cap if f < -cap else f
                if j + 1 < n:
                    t_in = max(k * (u[j] - u[j + 1]), 0.0)
            t.direction = direction
        return largest


def _sign(move: float, previous: float) -> float:
    """Direction of a move; a node that did not move keeps its last direction."""
    return 1.0 if move > 0.0 else -1.0 if move < 0.0 else previous


def _turned(du: list[list[float]], dirs: list[list[float]]) -> bool:
    """Did any node move against the direction its Dahl tangent assumed?"""
    for row, drow in zip(du, dirs, strict=True):
        for d, old in zip(row, drow, strict=True):
            if d * old < 0.0 or (d != 0.0 and old == 0.0):
                return True
    return False


def _dahl(force: float, travel: float, level: float, delta: float) -> float:
    """Dahl friction after ``travel``: exponential approach to +-``level`` over ``delta``."""
    if travel == 0.0:
        return force
    target = level if travel > 0.0 else -level
    return target + (force - target) * math.exp(-abs(travel) / delta)


class LumpedPlant:
    """Two knobs (phi1 anterior-posterior, phi2 right-left) of lumped Dahl tendon pairs.

    Implements :class:`simrig.plant.Plant`; build it with :func:`make_lumped_plant`.
    """

    def __init__(self, knobs: Sequence[LumpedKnobParams] = NOMINAL_KNOBS,
                 effects: LumpedEffects | None = None, n_lumps: int = 4) -> None:
        if len(knobs) != 2:
            raise PlantLoadError(f"knobs must list 2 knobs, got {len(knobs)}")
        if isinstance(n_lumps, bool) or not isinstance(n_lumps, int) or not 1 <= n_lumps <= 20:
            raise PlantLoadError(f"n_lumps must be an integer in 1..20, got {n_lumps!r}")
        self.knob_params = tuple(k.validated(f"knobs[{i}]") for i, k in enumerate(knobs))
        self.effects = (effects or LumpedEffects()).validated()
        self._knobs = [_Knob(p, self.effects, n_lumps) for p in self.knob_params]

    def reset(self) -> None:
        """Straight tip, unloaded tendons, no creep."""
        for k in self._knobs:
            k.reset()

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        """Move the knobs to ``knob_deg`` (degrees, shape (2,)) and settle."""
        q0, q1 = step_inputs(dt_s, knob_deg)
        k0, k1 = self._knobs
        tips = (k0.tip_rad, k1.tip_rad)
        loads = (sum(k0.proximal_N), sum(k1.proximal_N))
        tip0, tau0 = k0.step(dt_s, q0, tips[1], loads[1])
        tip1, tau1 = k1.step(dt_s, q1, tips[0], loads[0])
        return PlantStep(tip_deg=np.array([math.degrees(tip0), math.degrees(tip1)]),
                         knob_torque_Nm=np.array([tau0, tau1]))

    def reshape(self, sheath_curvature_deg: float | None = None,
                slack_delta_mm: Sequence[tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
                ) -> None:
        """Change the sheath's shape now (``simrig.scenario``): its total bend (wrap of the
        distal lumps and a shorter path) and per knob the tendons' slack (pos, neg) relative
        to the built values, in mm; the tendons keep their state."""
        eff = self.effects
        if sheath_curvature_deg is not None:
            eff = replace(eff, sheath_curvature_deg=float(sheath_curvature_deg)).validated()
        if len(slack_delta_mm) != 2:
            raise PlantLoadError(f"slack_delta_mm must list 2 knobs, got {len(slack_delta_mm)}")
        deltas = [(float(d_pos), float(d_neg)) for d_pos, d_neg in slack_delta_mm]
        for i, (knob, (d_pos, d_neg)) in enumerate(zip(self._knobs, deltas, strict=True)):
            if not (math.isfinite(d_pos) and math.isfinite(d_neg)):
                raise PlantLoadError(f"slack_delta_mm[{i}] must be finite, got {(d_pos, d_neg)}")
            if knob.p.slack_pos_mm + d_pos < 0.0 or knob.p.slack_neg_mm + d_neg < 0.0:
                raise PlantLoadError(f"slack_delta_mm[{i}] {(d_pos, d_neg)} makes a slack "
                                     "negative")
        self.effects = eff
        for knob, delta in zip(self._knobs, deltas, strict=True):
            knob.reshape(eff, delta)

    def tendon_tension_N(self) -> NDArray[np.float64]:
        """Tension of the four free segments, shape (2 knobs, 2 sides: pos, neg)."""
        return np.array([k.proximal_N for k in self._knobs])
