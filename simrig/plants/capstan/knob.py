"""One knob of the capstan plant: an antagonistic tendon pair, its sheath and bending section.

The equilibrium solve of each step lives here; :class:`_FastPath` extends the last full solve
cheaply while the pulley keeps moving the same way. Used by
:class:`simrig.plants.capstan.tendon_sheath.TendonSheathPlant`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from simrig.plants.capstan.params import Effects, KnobParams
from simrig.plants.capstan.tendon import (
    TendonGeometry,
    apply_pull,
    residual_m,
    settle_breakaway,
    solve_pull,
)

FloatArray = NDArray[np.float64]


class _FastPath:
    """What the last full solve of a tendon found, to extend it cheaply while nothing changes.

    While the pulley keeps moving the same way, every element keeps sliding and no further joint
    reaches its threshold, the residual is linear in the proximal tension with a known slope.
    """

    __slots__ = (
        "friction",
        "joint_friction_Nm",
        "joints",
        "limit_N",
        "other_N",
        "rho",
        "slope",
        "t_p",
        "target_m",
    )

    def __init__(
        self,
        rho: float,
        t_p: float,
        target_m: float,
        slope: float,
        limit_N: float,
        other_N: float,
        friction: tuple[FloatArray, FloatArray],
        joint_friction_Nm: FloatArray,
    ) -> None:
        self.rho = rho
        self.t_p = t_p
        self.target_m = target_m
        self.joints: FloatArray | None = None
        self.slope = slope
        self.limit_N = limit_N
        self.other_N = other_N
        self.friction = friction
        self.joint_friction_Nm = joint_friction_Nm


Friction = tuple[FloatArray, FloatArray, FloatArray, FloatArray]


class _Knob:
    """Mutable state and cached constants of one knob."""

    def __init__(self, p: KnobParams, eff: Effects, n_elements: int, n_joints: int) -> None:
        self.p = p
        compliance = (1.0 + eff.tendon_compliance) / p.tendon_stiffness_N
        seg = p.sheath_length_m / n_elements
        spread = np.linspace(0.4, 1.6, n_joints) if n_joints > 1 else np.ones(1)
        self.geom = TendonGeometry(
            free_compliance_m_per_N=p.free_length_m * compliance,
            element_compliance_m_per_N=np.full(n_elements, seg * compliance),
            offset_m=p.tendon_offset_mm * 1e-3,
            joint_stiffness_Nm_per_rad=np.full(n_joints, p.bend_stiffness_Nm_per_rad * n_joints),
        )
        self.kinetic_Nm = p.bend_friction_Nm * spread
        self.static_Nm = self.kinetic_Nm * p.bend_stiction_ratio
        self.has_stiction = p.bend_stiction_ratio > 1.0
        wrap_rad = math.radians(p.sheath_wrap_deg + eff.sheath_curvature_deg)
        # Friction exponent mu * wrap per element; the handle routing sits at the sheath entry.
        self.sheath_exponent = np.full(n_elements, p.sheath_friction * wrap_rad / n_elements)
        self.routing_exponent = np.zeros(n_elements)
        self.routing_exponent[0] = p.routing_friction * math.radians(p.routing_wrap_deg)
        self.radius_m = p.pulley_radius_mm * 1e-3
        curvature_slack_m = eff.lumen_clearance_mm * 1e-3 * math.radians(eff.sheath_curvature_deg)
        self.slack_pos_m = p.slack_pos_mm * 1e-3 + curvature_slack_m
        self.slack_neg_m = p.slack_neg_mm * 1e-3 + curvature_slack_m
        self.n_elements = n_elements
        self.n_joints = n_joints
        self.drag_per_element_N = np.full(n_elements, p.sheath_drag_N / n_elements)
        self.friction_static = self._friction(1.0)
        self.reset()

    def reshape(self, eff: Effects, slack_delta_mm: tuple[float, float]) -> None:
        """A new sheath shape mid-run: wrap and slack change, the tendons keep their tension."""
        p = self.p
        wrap_rad = math.radians(p.sheath_wrap_deg + eff.sheath_curvature_deg)
        self.sheath_exponent = np.full(self.n_elements, p.sheath_friction * wrap_rad
                                       / self.n_elements)
        curvature_slack_m = eff.lumen_clearance_mm * 1e-3 * math.radians(eff.sheath_curvature_deg)
        self.slack_pos_m = (p.slack_pos_mm + slack_delta_mm[0]) * 1e-3 + curvature_slack_m
        self.slack_neg_m = (p.slack_neg_mm + slack_delta_mm[1]) * 1e-3 + curvature_slack_m
        self.friction_static = self._friction(1.0)
        for side in (0, 1):  # cached solutions belong to the old shape
            self._last[side] = None
            self._fast[side] = None

    def _friction(self, sheath_scale: float) -> Friction:
        """(G, H) for pulling and for the mirrored release, sheath friction scaled."""
        gain = np.exp(-np.cumsum(sheath_scale * self.sheath_exponent + self.routing_exponent))
        inv = 1.0 / gain
        h = self.drag_per_element_N
        return gain, gain * np.cumsum(h * inv), inv, inv * np.cumsum(h * gain)

    def reset(self) -> None:
        self.tension_N = np.zeros((2, self.n_elements))
        self.joints_rad = np.zeros(self.n_joints)
        self.joint_dir = np.zeros(self.n_joints)
        """Direction each joint slid in during the last step (0: stuck, static friction)."""
        self.tip_rad = 0.0
        self.knob_rad: float | None = None
        self.handle_dir = 0.0
        self.handle_slip_deg = 0.0
        # Per tendon (0: "+", 1: "-"), plain floats for speed: proximal tension, distal tension,
        # stretch (free segment + sheath), creep.
        self.proximal = [0.0, 0.0]
        self.distal = [0.0, 0.0]
        self.stretch = [0.0, 0.0]
        self.creep_m = [0.0, 0.0]
        self._last: list[tuple[float, float, FloatArray] | None] = [None, None]
        self._fast: list[_FastPath | None] = [None, None]

    def step(
        self, dt_s: float, knob_rad: float, other_tip_rad: float, eff: Effects
    ) -> tuple[float, float]:
        """Advance to ``knob_rad``; returns (tip angle rad, knob torque Nm)."""
        prev = knob_rad if self.knob_rad is None else self.knob_rad
        speed = (knob_rad - prev) / dt_s if dt_s > 0.0 else 0.0
        self.knob_rad = knob_rad
        friction = self.friction_static
        if eff.rate_dependence > 0.0:
            rel = eff.rate_dependence * abs(math.degrees(speed)) / eff.rate_reference_deg_s
            friction = self._friction(1.0 + rel)

        slack_pos = self.slack_pos_m + self.creep_m[0]
        slack_neg = self.slack_neg_m + self.creep_m[1]
        if eff.coupling > 0.0:
            rb = self.geom.offset_m
            twist = rb * math.sin(math.radians(eff.coupling_tendon_twist_deg)) * other_tip_rad
            short = eff.coupling_shortening_mm_per_rad2 * 1e-3 * other_tip_rad**2
            slack_pos += eff.coupling * (short - twist)
            slack_neg += eff.coupling * (short + twist)

        before = self.joints_rad
        draw_in = self.radius_m * knob_rad
        self._solve_tendon(0, 1.0, draw_in - slack_pos, friction)
        self._solve_tendon(1, -1.0, -draw_in - slack_neg, friction)
        if self.has_stiction:
            if self.joints_rad is not before:
                self.joint_dir = np.sign(self.joints_rad - before)
            elif self.joint_dir.any():
                self.joint_dir = np.zeros(self.n_joints)

        if eff.creep_mm_per_N_s > 0.0 and dt_s > 0.0:
            rate = eff.creep_mm_per_N_s * 1e-3 * dt_s
            self.creep_m = [
                self.creep_m[0] + rate * self.proximal[0],
                self.creep_m[1] + rate * self.proximal[1],
            ]
        torque = self.radius_m * (self.proximal[0] - self.proximal[1])
        torque += self._handle_friction_Nm(math.degrees(knob_rad - prev), math.degrees(speed))
        return self.tip_rad, torque

    def _handle_friction_Nm(self, step_deg: float, speed_deg_s: float) -> float:
        """Knob friction: static after a reversal or stop, kinetic after some slip."""
        p = self.p
        if step_deg == 0.0:
            self.handle_slip_deg = 0.0
        elif (step_deg > 0.0) != (self.handle_dir > 0.0):
            self.handle_dir = 1.0 if step_deg > 0.0 else -1.0
            self.handle_slip_deg = abs(step_deg)
        else:
            self.handle_slip_deg += abs(step_deg)
        level = p.handle_friction_Nm + (p.handle_stiction_Nm - p.handle_friction_Nm) * math.exp(
            -self.handle_slip_deg / p.handle_slip_deg
        )
        return level * math.tanh(speed_deg_s / 0.2)

    def _solve_tendon(self, side: int, sign: float, target_m: float, friction: Friction) -> None:
        """Bring one tendon (``sign`` +1: pulled by positive rotation) into equilibrium."""
        other = self.distal[1 - side]
        last = self._last[side]
        if (
            last is not None
            and last[0] == target_m
            and last[1] == other
            and last[2] is self.joints_rad
            and friction is self.friction_static
        ):
            return  # nothing acting on this tendon changed
        if self.proximal[side] == 0.0 and (
            self.stretch[side] + sign * self.geom.offset_m * self.tip_rad >= target_m
        ):
            pass  # slack, and staying slack
        elif not self._extend_fast(side, sign, target_m, other, friction):
            self._fast[side] = None
            self._full_solve(side, sign, target_m, other, friction)
        self._last[side] = (target_m, other, self.joints_rad)
        fast = self._fast[side]
        if fast is not None:
            fast.joints = self.joints_rad

    def _store(
        self, side: int, rho: float, sign: float, t_p: float, prof: FloatArray, jnt: FloatArray
    ) -> None:
        """Write a pull-frame solution back into the knob's state."""
        self.proximal[side] = rho * t_p
        row = rho * prof
        self.tension_N[side] = row
        self.distal[side] = float(row[-1])
        self.joints_rad = (sign * rho) * jnt
        self.tip_rad = (sign * rho) * float(jnt.sum())

    def _full_solve(
        self, side: int, sign: float, target_m: float, other: float, friction: Friction
    ) -> None:
        tension = self.tension_N[side]
        joints = sign * self.joints_rad
        t_p = self.proximal[side]
        f0 = residual_m(self.geom, tension, t_p, joints, target_m)
        if f0 == 0.0 or (t_p == 0.0 and f0 > 0.0):
            return  # in equilibrium, or slack and staying slack
        rho = 1.0 if f0 < 0.0 else -1.0
        g, h = (friction[0], friction[1]) if rho > 0.0 else (friction[2], friction[3])
        # A joint already sliding this way needs only kinetic friction, a stuck one static.
        sliding = self.joint_dir == sign * rho if self.has_stiction else None
        mf = (
            self.kinetic_Nm
            if sliding is None
            else np.where(sliding, self.kinetic_Nm, self.static_Nm)
        )
        other_r = rho * other
        sol = solve_pull(self.geom, g, h, rho * tension, rho * joints, mf, other_r, rho * target_m)
        t_new, prof, jnt = sol.proximal_N, sol.tension_N, sol.joints_rad
        if rho * t_new < 0.0:  # a tendon cannot push: it goes slack
            t_new = 0.0
            prof, jnt = apply_pull(self.geom, g, h, rho * tension, rho * joints, mf, other_r, 0.0)
        elif sol.all_slip:
            freed = None if sliding is None else (jnt != rho * joints) & ~sliding
            if freed is not None and freed.any():
                t_new, prof, jnt = settle_breakaway(
                    self.geom, g, h, jnt, freed, self.kinetic_Nm, other_r, rho * target_m
                )
            else:
                fast_mf = np.where(jnt != rho * joints, self.kinetic_Nm, mf)
                self._fast[side] = _FastPath(
                    rho, t_new, target_m, sol.slope_m_per_N, sol.limit_N, other, (g, h), fast_mf
                )
        self._store(side, rho, sign, t_new, prof, jnt)
        self.stretch[side] = self.proximal[side] * self.geom.free_compliance_m_per_N + float(
            self.tension_N[side] @ self.geom.element_compliance_m_per_N
        )

    def _extend_fast(
        self, side: int, sign: float, target_m: float, other: float, friction: Friction
    ) -> bool:
        fast = self._fast[side]
        if (
            fast is None
            or fast.joints is not self.joints_rad
            or friction is not self.friction_static
            or other != fast.other_N
        ):
            return False
        rho = fast.rho
        t_new = fast.t_p + rho * (target_m - fast.target_m) / fast.slope
        if not (fast.t_p < t_new <= fast.limit_N) or rho * t_new < 0.0:
            return False  # reversal, a new threshold, or the tendon goes slack: solve in full
        g, h = fast.friction
        prof = t_new * g - h
        k = self.geom.joint_stiffness_Nm_per_rad
        turned = (self.geom.offset_m * (float(prof[-1]) - rho * other) - fast.joint_friction_Nm) / k
        jnt = np.maximum((sign * rho) * self.joints_rad, turned)
        self._store(side, rho, sign, t_new, prof, jnt)
        # The residual is zero at the solution: stretch = draw-in - distal travel.
        self.stretch[side] = target_m - sign * self.geom.offset_m * self.tip_rad
        fast.t_p = t_new
        fast.target_m = target_m
        return True
