"""The rackgrease plant: a rack-and-pinion handle whose rack cocks in its guide, an eddy-current
damper on each knob, steel ropes with slack in grease-packed lumens (Bingham yield and flow, a
pre-sliding gel, boundary capstan friction), a section carrying a heavy transducer head that
gravity bends (both planes share the head's lever: a coupling; the section's bend adds wrap).

Per plane, the section's bend is found by a safeguarded Newton on its moment balance; each rope
is solved in closed form for a trial bend (its distal tension is piecewise linear in the bend).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantStep, step_inputs
from simrig.plants.rackgrease.laws import (
    coulomb_ratio,
    eddy_torque_Nm,
    grease_moment,
    guide_friction_N,
    head_moment_Nmm,
    solve_rope,
)
from simrig.plants.rackgrease.params import NOMINAL_KNOBS, KnobConstants, knob_constants

RAD_PER_DEG = math.pi / 180.0
GUIDE_SPEED_MM_S = 0.05
"""Rack speed below which the guide's friction is taken as partly stuck (regularised sign)."""


class _Plane:
    """One knob's drive train and its plane of the section."""

    def __init__(self, k: KnobConstants) -> None:
        if k.pinion_radius_mm <= 0 or k.tendon_stiffness_N <= 0 or k.tendon_offset_mm <= 0:
            raise ValueError("rackgrease: pinion radius, rope stiffness and offset must be > 0")
        if k.bend_stiffness_Nmm_per_rad <= 0 or k.contact_stiffness_N_per_mm <= 0:
            raise ValueError("rackgrease: section and contact stiffness must be > 0")
        if not 0.0 < k.contact_fraction < 1.0 or k.guide_length_mm <= 0:
            raise ValueError("rackgrease: contact_fraction in (0, 1), guide length > 0")
        if min(k.slack_pos_mm, k.slack_neg_mm, k.sheath_friction, k.sheath_drag_N,
               k.grease_viscosity_N_s_per_mm) < 0:
            raise ValueError("rackgrease: slack, friction, yield and viscosity must be >= 0")
        self.k = k
        proximal_mm = 1000.0 * (k.free_length_m + k.contact_fraction * k.sheath_length_m)
        distal_mm = 1000.0 * ((1.0 - k.contact_fraction) * k.sheath_length_m
                              + k.section_length_m)
        self.k1 = k.tendon_stiffness_N / proximal_mm
        self.k2 = k.tendon_stiffness_N / distal_mm
        self.slack = [k.slack_pos_mm, k.slack_neg_mm]
        self.reset()

    def reset(self) -> None:
        self.anchors_mm = [0.0, 0.0]
        """Each rope's contact anchor (positive-side rope, negative-side rope)."""
        self.nodes_mm = [0.0, 0.0]
        self.bend_rad = 0.0
        self.gel_anchor_rad = 0.0
        self.knob_deg = 0.0
        self.tensions_N = (0.0, 0.0)

    def solve(self, dt_s: float, knob_deg: float, other_rad: float, wrap_rad: float
              ) -> tuple[float, float]:
        """Advance to ``knob_deg``; the section's bend (rad) and the knob's torque (Nm)."""
        k = self.k
        rack_mm = k.pinion_radius_mm * knob_deg * RAD_PER_DEG
        draw_pos, draw_neg = rack_mm - self.slack[0], -rack_mm - self.slack[1]
        coulomb = coulomb_ratio(k.sheath_friction,
                                wrap_rad + k.section_wrap_fraction
                                * math.hypot(self.bend_rad, other_rad))
        step = max(dt_s, 1e-9)
        viscous = k.grease_viscosity_N_s_per_mm / step
        section_viscous = k.section_viscosity_Nmm_s_per_rad / step
        r, ks = k.tendon_offset_mm, k.bend_stiffness_Nmm_per_rad
        k1, k2, kc, drag = self.k1, self.k2, k.contact_stiffness_N_per_mm, k.sheath_drag_N
        z_pos, z_neg = self.anchors_mm
        theta = self.bend_rad
        lo, hi = -math.inf, math.inf
        for _ in range(40):
            pos = solve_rope(z_pos, draw_pos, r * theta, k1, k2, kc, drag, coulomb, viscous)
            neg = solve_rope(z_neg, draw_neg, -r * theta, k1, k2, kc, drag, coulomb, viscous)
            grease = grease_moment(theta, self.gel_anchor_rad, k.section_gel_Nmm_per_rad,
                                   k.section_yield_Nmm, section_viscous)
            residual = (r * (pos[1] - neg[1]) - ks * theta - grease[0]
                        + head_moment_Nmm(theta, other_rad, k.head_moment_Nmm))
            if residual > 0.0:
                lo = theta
            else:
                hi = theta
            nxt = theta - residual / (r * r * (pos[2] + neg[2]) - ks - grease[1])
            if not lo < nxt < hi and math.isfinite(lo) and math.isfinite(hi):
                nxt = 0.5 * (lo + hi)  # a kink between two regions: bisect the bracket
            if abs(nxt - theta) < 1e-10:
                break
            theta = nxt
        self.nodes_mm = [pos[3], neg[3]]
        self.anchors_mm = [pos[4], neg[4]]
        self.gel_anchor_rad = grease[2]
        self.bend_rad = theta
        self.tensions_N = (pos[0], neg[0])
        speed = (knob_deg - self.knob_deg) / dt_s if dt_s > 0 else 0.0
        self.knob_deg = knob_deg
        return theta, self._torque_Nm(pos[0], neg[0], speed)

    def _torque_Nm(self, pos_N: float, neg_N: float, speed_deg_s: float) -> float:
        """The ropes' pull on the pinion, the cocked rack's guide friction, the guide preload
        and the eddy-current drag, all against the knob's motion."""
        k = self.k
        rack_speed = k.pinion_radius_mm * speed_deg_s * RAD_PER_DEG
        direction = math.tanh(rack_speed / GUIDE_SPEED_MM_S)
        guide_N = guide_friction_N(pos_N + neg_N, k.guide_friction, k.rack_offset_mm,
                                   k.guide_length_mm)
        arm_m = k.pinion_radius_mm / 1000.0
        return (arm_m * (pos_N - neg_N + direction * guide_N)
                + direction * k.handle_friction_Nm
                + eddy_torque_Nm(speed_deg_s, k.eddy_peak_Nm, k.eddy_critical_deg_s))


class RackGreasePlant:
    """Two knobs (phi1 anterior-posterior, phi2 right-left) through rack-and-pinion handles and
    grease-packed lumens to a section with a heavy head."""

    def __init__(self, knobs: Sequence[KnobConstants | dict[str, float]] | None = None,
                 sheath_curvature_deg: float = 0.0) -> None:
        constants = [knob_constants(v) for v in (knobs if knobs is not None else NOMINAL_KNOBS)]
        if len(constants) != 2:
            raise ValueError(f"rackgrease takes 2 knobs, got {len(constants)}")
        self.planes = [_Plane(c) for c in constants]
        self.sheath_curvature_deg = float(sheath_curvature_deg)

    def reset(self) -> None:
        for p in self.planes:
            p.reset()

    def reshape(self, **changes: Any) -> None:
        """Mid-run shape changes: ``sheath_curvature_deg`` (extra shaft curve, deg) and
        ``slack_delta_mm`` (((pos, neg), (pos, neg)) added to each rope's slack)."""
        unknown = set(changes) - {"sheath_curvature_deg", "slack_delta_mm"}
        if unknown:
            raise ValueError(f"rackgrease cannot reshape {sorted(unknown)}")
        if "sheath_curvature_deg" in changes:
            self.sheath_curvature_deg = float(changes["sheath_curvature_deg"])
        if "slack_delta_mm" in changes:
            for plane, delta in zip(self.planes, changes["slack_delta_mm"], strict=True):
                plane.slack = [plane.slack[0] + float(delta[0]), plane.slack[1] + float(delta[1])]

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q0, q1 = step_inputs(dt_s, knob_deg)
        a, b = self.planes
        extra = self.sheath_curvature_deg * RAD_PER_DEG
        other_b = b.bend_rad
        theta_a, tau_a = a.solve(dt_s, q0, other_b, a.k.sheath_wrap_deg * RAD_PER_DEG + extra)
        theta_b, tau_b = b.solve(dt_s, q1, theta_a, b.k.sheath_wrap_deg * RAD_PER_DEG + extra)
        return PlantStep(np.array([theta_a / RAD_PER_DEG, theta_b / RAD_PER_DEG]),
                         np.array([tau_a, tau_b]))

    @property
    def tensions_N(self) -> list[tuple[float, float]]:
        """Proximal tension of each knob's (positive, negative) rope: diagnostics."""
        return [p.tensions_N for p in self.planes]


def make_rackgrease_plant(knobs: Sequence[KnobConstants | dict[str, float]] | None = None,
                          sheath_curvature_deg: float = 0.0) -> RackGreasePlant:
    """Factory for ``simrig.plant.load_plant`` and the family."""
    return RackGreasePlant(knobs, sheath_curvature_deg)
