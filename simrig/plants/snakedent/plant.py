"""The snakedent plant: a snake-bone section of rolling vertebrae behind detented knobs.

Per plane, quasi-static each step: the two ropes' lumen contacts in closed form
(:func:`laws.lumen_contact`), then the stack's bend from its moment balance with a friction
band at the joints (Newton on the bend, bracketed), the other plane's last state for the
coupling (its bend takes up this plane's ropes, its ropes straighten this plane's joints and
press the stack harder).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.snakedent.laws import (
    detent_torque_Nm,
    lumen_contact,
    rope_arm_mm,
    rope_lengthening_mm,
)
from simrig.plants.snakedent.params import NOMINAL_KNOBS, SnakeDentKnob, knob_from

_KNOB_SPEED_DEG_S = 2.0
"""Knob speed over which the seal's friction builds up (tanh: deterministic at a reversal)."""
_TOL_NMM = 1e-4
_MAX_ITER = 12


class SnakeDentPlant:
    """Two planes of rolling vertebrae, each pulled by a pair of ropes off a detented knob."""

    def __init__(self, knobs: Sequence[SnakeDentKnob], sheath_curvature_deg: float = 0.0,
                 coupling: float = 0.0) -> None:
        self.knobs = tuple(knobs)
        self.sheath_curvature_deg = sheath_curvature_deg
        # the other plane's take-up on this plane's ropes as a share of what the vertebrae's
        # geometry gives (``coupling`` adds to it: rope holes set off their plane)
        self.cross_takeup_share = 1.0 + coupling
        self._slack_extra = [[0.0, 0.0], [0.0, 0.0]]
        self._constants()
        self.reset()

    def _constants(self) -> None:
        self._k_half, self._ratio, self._depth = [], [], []
        for k in self.knobs:
            length_mm = 1000.0 * (k.sheath_length_m + k.free_length_m)
            self._k_half.append(2.0 * k.tendon_stiffness_N / length_mm)
            wrap = math.radians(k.sheath_wrap_deg + self.sheath_curvature_deg)
            self._ratio.append(math.exp(k.sheath_friction * wrap))
            self._depth.append(k.roll_radius_mm - k.hole_depth_mm)

    def reset(self) -> None:
        """Straight stack, ropes unloaded, knobs at 0 (a reshape stays)."""
        self.theta_rad = [0.0, 0.0]
        self.z_mm = [[0.0, 0.0], [0.0, 0.0]]
        self.proximal_N = [[0.0, 0.0], [0.0, 0.0]]
        self.distal_N = [[0.0, 0.0], [0.0, 0.0]]
        self._knob_deg = [0.0, 0.0]

    def reshape(self, **changes: Any) -> None:
        """Shape changes mid-run: ``slack_delta_mm=((pos, neg), (pos, neg))`` (slack grown per
        rope) and ``sheath_curvature_deg`` (the sheath laid in a curve: more wrap)."""
        for name, value in changes.items():
            if name == "slack_delta_mm":
                for i in (0, 1):
                    for j in (0, 1):
                        self._slack_extra[i][j] += float(value[i][j])
            elif name == "sheath_curvature_deg":
                self.sheath_curvature_deg = float(value)
                self._constants()
            else:
                raise ValueError(f"cannot reshape {name!r}: snakedent takes slack_delta_mm, "
                                 "sheath_curvature_deg")

    def _plane(self, i: int, q_deg: float, theta_rad: float
               ) -> tuple[float, list[tuple[float, float, float, float]]]:
        """Moment left over at the joints of plane ``i`` bent by ``theta_rad`` per joint (N mm,
        friction not included), its stiffness, and both ropes' contact answers."""
        k, o = self.knobs[i], self.knobs[1 - i]
        c, c_o = self._depth[i], self._depth[1 - i]
        take_up = self.cross_takeup_share * o.joints * rope_lengthening_mm(
            self.theta_rad[1 - i], 0.0, c_o)
        draw = math.radians(q_deg) * k.drum_radius_mm
        slack = (k.slack_pos_mm + self._slack_extra[i][0],
                 k.slack_neg_mm + self._slack_extra[i][1])
        ropes = []
        for side, sign in ((0, 1.0), (1, -1.0)):
            used = -k.joints * rope_lengthening_mm(theta_rad, sign * k.tendon_offset_mm, c)
            ropes.append(lumen_contact(sign * draw - slack[side], used - take_up,
                                       self.z_mm[i][side], self._k_half[i], self._ratio[i],
                                       k.sheath_drag_N))
        arm_p = rope_arm_mm(theta_rad, k.tendon_offset_mm, c)
        arm_n = rope_arm_mm(-theta_rad, k.tendon_offset_mm, c)
        other_N = self.distal_N[1 - i][0] + self.distal_N[1 - i][1]
        s = math.sin(0.5 * theta_rad)
        moment = (ropes[0][2] * arm_p - ropes[1][2] * arm_n - other_N * c * s
                  - k.bend_stiffness_Nmm_per_rad * theta_rad)
        return moment, ropes

    def _friction_Nmm(self, i: int, ropes: list[tuple[float, float, float, float]]) -> float:
        k = self.knobs[i]
        load = (k.joint_preload_N + ropes[0][2] + ropes[1][2] + self.distal_N[1 - i][0]
                + self.distal_N[1 - i][1])
        return k.joint_friction_mm * load

    def _bend(self, i: int, q_deg: float) -> tuple[float, list[tuple[float, float, float, float]]]:
        """The bend of plane ``i`` after this step and its ropes' contacts."""
        theta = self.theta_rad[i]
        moment, ropes = self._plane(i, q_deg, theta)
        band = self._friction_Nmm(i, ropes)
        if abs(moment) <= band:
            return theta, ropes
        sign = 1.0 if moment > 0.0 else -1.0
        # the residual r(t) = moment(t) - sign * band(t) falls with t; bracket it
        lo, hi = (theta, math.pi) if sign > 0.0 else (-math.pi, theta)
        k = self.knobs[i]
        t = theta
        r = moment - sign * band
        for _ in range(_MAX_ITER):
            if sign * r > 0.0:
                lo, hi = (t, hi) if sign > 0.0 else (lo, t)
            else:
                lo, hi = (lo, t) if sign > 0.0 else (t, hi)
            stiff = k.bend_stiffness_Nmm_per_rad + k.joints * (
                ropes[0][3] * rope_arm_mm(t, k.tendon_offset_mm, self._depth[i]) ** 2
                + ropes[1][3] * rope_arm_mm(-t, k.tendon_offset_mm, self._depth[i]) ** 2)
            t_new = t + r / stiff
            if not lo < t_new < hi:
                t_new = 0.5 * (lo + hi)
            t = t_new
            moment, ropes = self._plane(i, q_deg, t)
            r = moment - sign * self._friction_Nmm(i, ropes)
            if abs(r) < _TOL_NMM or hi - lo < 1e-9:
                break
        return t, ropes

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q = step_inputs(dt_s, knob_deg)
        tip = np.empty(2)
        torque = np.empty(2)
        for i in (0, 1):
            k = self.knobs[i]
            theta, ropes = self._bend(i, q[i])
            self.theta_rad[i] = theta
            self.z_mm[i] = [ropes[0][0], ropes[1][0]]
            self.proximal_N[i] = [ropes[0][1], ropes[1][1]]
            self.distal_N[i] = [ropes[0][2], ropes[1][2]]
            speed = (q[i] - self._knob_deg[i]) / dt_s if dt_s > 0.0 else 0.0
            self._knob_deg[i] = q[i]
            torque[i] = (k.drum_radius_mm * (ropes[0][1] - ropes[1][1]) / 1000.0
                         + k.handle_friction_Nm * math.tanh(speed / _KNOB_SPEED_DEG_S)
                         + detent_torque_Nm(q[i], k.detent_torque_Nm, k.detent_pitch_deg))
            tip[i] = math.degrees(k.joints * theta)
        return PlantStep(tip, torque)


def make_snakedent_plant(knobs: Sequence[Mapping[str, Any]] | None = None,
                         sheath_curvature_deg: float = 0.0,
                         coupling: float = 0.0) -> SnakeDentPlant:
    """The snakedent plant; ``knobs`` are two dicts of :class:`SnakeDentKnob` overrides;
    ``coupling`` adds that many times the other plane's take-up to every rope (0: as written)."""
    given = list(knobs) if knobs is not None else [{}, {}]
    if len(given) != 2:
        raise PlantLoadError(f"snakedent takes 2 knobs, got {len(given)}")
    if not (math.isfinite(sheath_curvature_deg) and sheath_curvature_deg >= 0.0):
        raise PlantLoadError(f"snakedent sheath_curvature_deg must be >= 0, got "
                             f"{sheath_curvature_deg!r}")
    if not (math.isfinite(coupling) and coupling >= 0.0):
        raise PlantLoadError(f"snakedent coupling must be >= 0, got {coupling!r}")
    return SnakeDentPlant([knob_from(v, base) for v, base in zip(given, NOMINAL_KNOBS,
                                                                  strict=True)],
                          float(sheath_curvature_deg), float(coupling))
