"""The beltbraid plant: a belt-driven, spring-return handle, steel ropes in a braided lumen
with distributed microslip, a braided shaft whose crossings slip, an asymmetrically notched tube.

Per knob: knob -> belt loop (wind-up, Reynolds creep) -> drum of radius r -> rope A (pulled by a
positive knob angle) and rope B. Each rope is two springs meeting at the lumen's friction centroid
(drum side: the free length and the first part of the sheath; tip side: the rest), its slack at
the drum. The node's friction is ``C w``: capacity ``C = drag + tanh(mu wrap / 2) (T_drum + T_tip)``
(at full slip the capstan ratio exp(mu wrap) between the rope's two ends) and the Bouc-Wen
fraction ``w`` of :func:`laws.microslip`. A bulkhead seal drags each taut rope at the handle
(knob load only: the rope piece through it is short and stiff). The section's plane balances the
two ropes' tip tensions on the lumen radius against a stiffness that differs by side (notches cut
deeper on the positive side). All four ropes' reaction shortens the braided shaft (Preisach
relays plus an elastic part), which takes draw from every rope: the planes' coupling.

Solve per step and plane: the node's friction linearised at its tangent (implicit), each rope's
node and tip tension then linear in the bend, the bend from the section's balance in closed form,
the ropes' taut/slack flags iterated to agreement (<= 4 passes). Belt wind-up, capacity and shaft
shortening lag one step (their loop gains are < 0.2).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantStep, step_inputs
from simrig.plants.beltbraid.laws import (
    BraidRelays,
    microslip,
    microslip_rate,
    return_spring_Nm,
)
from simrig.plants.beltbraid.params import NOMINAL_KNOBS, KnobParams, knob_params

_SEAL_SPEED_DEG_S = 3.0
_ROPE_SEAL_SPEED_MM_S = 0.05
_SIDES = (1.0, -1.0)
_KINK_MM = 1e-9
_CAP_JUMP_N = 0.5  # rope A (pulled by a positive knob angle), rope B


def _flag(stretch_mm: float, was: bool) -> bool:
    """Taut if stretched; a node on the kink (round-off) keeps the flag it was solved with."""
    if abs(stretch_mm) < _KINK_MM:
        return was
    return stretch_mm > 0.0


class _Knob:
    """One knob's state and its per-step solve."""

    def __init__(self, p: KnobParams) -> None:
        self.p = p
        self.slack_mm = [p.slack_pos_mm, p.slack_neg_mm]
        self.reset()

    def reset(self) -> None:
        self.knob_deg = 0.0
        self.creep_rad = 0.0
        self.drum_torque_Nm = 0.0
        self.theta_rad = 0.0
        self.node_mm = [0.0, 0.0]
        self.w = [0.0, 0.0]
        self.direction = [1.0, -1.0]
        self.drum_N = [0.0, 0.0]
        self.tip_N = [0.0, 0.0]
        self.seal_Nm = 0.0
        self.drum_rad = 0.0
        self.rope_speed_mm_s = 0.0
        self.fallbacks = 0
        self.cap_N = [self.p.sheath_drag_N, self.p.sheath_drag_N]

    def capacity_N(self, j: int, wrap_rad: float) -> float:
        """Friction at full slip: the capstan ratio exp(mu wrap) on the mean tension, plus drag."""
        p = self.p
        mean_N = 0.5 * (self.drum_N[j] + self.tip_N[j])
        return p.sheath_drag_N + 2.0 * math.tanh(0.5 * p.sheath_friction * wrap_rad) * mean_N

    def slip_length_mm(self, j: int, wrap_rad: float) -> float:
        """Slip that mobilises the lumen: the rope stretches along the whole lumen first."""
        p = self.p
        mean_N = 0.5 * (self.drum_N[j] + self.tip_N[j])
        return p.microslip_floor_mm + (p.sheath_friction * wrap_rad * p.microslip_length_m * 1000.0
                                       * mean_N / (2.0 * p.tendon_stiffness_N))

    def step(self, dt_s: float, knob_deg: float, shortening_mm: float, wrap_rad: float) -> None:
        p = self.p
        dq_rad = math.radians(knob_deg - self.knob_deg)
        self.creep_rad += p.belt_creep_per_Nm * self.drum_torque_Nm * abs(dq_rad)
        if dt_s > 0.0:
            speed = (knob_deg - self.knob_deg) / dt_s
            self.seal_Nm = p.handle_friction_Nm * math.tanh(speed / _SEAL_SPEED_DEG_S)
        self.knob_deg = knob_deg
        drum_rad = (math.radians(knob_deg) - self.creep_rad
                    - self.drum_torque_Nm / p.belt_stiffness_Nm_per_rad)
        r = p.drum_radius_mm
        d = p.tendon_offset_mm
        k1 = p.tendon_stiffness_N / (p.free_length_m * 1000.0
                                     + p.contact_fraction * p.sheath_length_m * 1000.0)
        k2 = p.tendon_stiffness_N / ((1.0 - p.contact_fraction) * p.sheath_length_m * 1000.0)
        draw = [sigma * r * drum_rad - self.slack_mm[j] - shortening_mm
                for j, sigma in enumerate(_SIDES)]
        # the capacity lags a step; a jump larger than _CAP_JUMP_N is averaged with the last one
        # used, so that a knob moved far in one step cannot feed a two-step oscillation between
        # tension and capacity (smooth motion changes it by far less per step)
        cap = [self.capacity_N(j, wrap_rad) for j in (0, 1)]
        for j in (0, 1):
            if abs(cap[j] - self.cap_N[j]) > _CAP_JUMP_N:
                cap[j] = 0.5 * (cap[j] + self.cap_N[j])
        self.cap_N = list(cap)
        slip_len = [self.slip_length_mm(j, wrap_rad) for j in (0, 1)]
        rate = [microslip_rate(self.w[j], self.direction[j], slip_len[j]) for j in (0, 1)]
        taut_drum = [draw[j] > self.node_mm[j] for j in (0, 1)]
        taut_tip = [self.node_mm[j] > _SIDES[j] * d * self.theta_rad for j in (0, 1)]
        theta = self.theta_rad
        node = list(self.node_mm)
        w_solve = list(self.w)
        converged = False
        for _ in range(6):
            # node = a + b theta; tip tension = e + f theta (per rope, flags fixed)
            e_sum = 0.0
            f_sum = 0.0
            ab: list[tuple[float, float]] = []
            for j, sigma in enumerate(_SIDES):
                kd = k1 if taut_drum[j] else 0.0
                kt = k2 if taut_tip[j] else 0.0
                cg = cap[j] * rate[j]
                den = kd + kt + cg
                if den <= 0.0:
                    ab.append((self.node_mm[j], 0.0))
                    continue
                a = (kd * draw[j] - cap[j] * w_solve[j] + cg * self.node_mm[j]) / den
                b = kt * sigma * d / den
                ab.append((a, b))
                e_sum += sigma * kt * a
                f_sum += sigma * kt * (b - sigma * d)
            stiff = p.bend_stiffness_Nmm_per_rad * (1.0 if e_sum >= 0.0 else p.notch_asymmetry)
            theta = d * e_sum / (stiff - d * f_sum)
            node = [a + b * theta for a, b in ab]
            new_drum = [_flag(draw[j] - node[j], taut_drum[j]) for j in (0, 1)]
            new_tip = [_flag(node[j] - _SIDES[j] * d * theta, taut_tip[j]) for j in (0, 1)]
            sliding = False
            for j in (0, 1):  # the linearised friction cannot pass the capacity: the node slides
                w_lin = w_solve[j] + rate[j] * (node[j] - self.node_mm[j])
                if abs(w_lin) > 1.0:
                    w_solve[j], rate[j], sliding = math.copysign(1.0, w_lin), 0.0, True
            if new_drum == taut_drum and new_tip == taut_tip and not sliding:
                converged = True
                break
            taut_drum, taut_tip = new_drum, new_tip
        if not converged:  # the flags cycle: bracket the bend instead (rare)
            self.fallbacks += 1
            theta, node = self._bracketed(draw, cap, rate, w_solve, k1, k2)
        for j, sigma in enumerate(_SIDES):
            drum_N = k1 * max(draw[j] - node[j], 0.0)
            tip_N = k2 * max(node[j] - sigma * d * theta, 0.0)
            slip = node[j] - self.node_mm[j]
            if drum_N == 0.0 and tip_N == 0.0:
                # a loose rope: nothing loads the contact, its microslip springs back
                node[j] = self.node_mm[j] - self.w[j] * slip_len[j]
                self.w[j] = 0.0
            else:
                self.w[j] = microslip(self.w[j], slip, slip_len[j])
                if slip != 0.0:
                    self.direction[j] = 1.0 if slip > 0.0 else -1.0
            self.drum_N[j] = drum_N
            self.tip_N[j] = tip_N
        self.node_mm = node
        self.theta_rad = theta
        self.drum_rad = drum_rad
        if dt_s > 0.0:  # the knob's speed (the belt's wind-up lags it by a step)
            self.rope_speed_mm_s = r * dq_rad / dt_s
        pull = [0.0, 0.0]
        for j, sigma in enumerate(_SIDES):
            if self.drum_N[j] > 0.0:  # the seal drags a taut rope sliding through it
                seal = p.seal_drag_N * math.tanh(sigma * self.rope_speed_mm_s
                                                 / _ROPE_SEAL_SPEED_MM_S)
                pull[j] = max(self.drum_N[j] + seal, 0.0)
        self.drum_torque_Nm = r * (pull[0] - pull[1]) / 1000.0

    def _node(self, j: int, theta: float, draw: list[float], cap: list[float],
              rate: list[float], w: list[float], k1: float, k2: float) -> float:
        """Rope ``j``'s node at bend ``theta``: the one consistent piece of its monotone balance."""
        end = _SIDES[j] * self.p.tendon_offset_mm * theta
        cg = cap[j] * rate[j]
        for kd, kt in ((k1, 0.0), (0.0, k2), (k1, k2), (0.0, 0.0)):
            den = kd + kt + cg
            if den <= 0.0:
                continue
            z = (kd * draw[j] + kt * end - cap[j] * w[j] + cg * self.node_mm[j]) / den
            if (_flag(draw[j] - z, kd > 0.0) == (kd > 0.0)
                    and _flag(z - end, kt > 0.0) == (kt > 0.0)):
                return z
        # the root sits on a kink: the one where the balance changes sign
        for z in (draw[j], end):
            if abs(-cap[j] * (w[j] + rate[j] * (z - self.node_mm[j]))
                   - k2 * max(z - end, 0.0) + k1 * max(draw[j] - z, 0.0)) < 1e-6:
                return z
        return self.node_mm[j]

    def _bracketed(self, draw: list[float], cap: list[float], rate: list[float],
                   w: list[float], k1: float, k2: float) -> tuple[float, list[float]]:
        """The bend where the section balances the ropes (decreasing residual; Illinois)."""
        p = self.p
        d = p.tendon_offset_mm

        def residual(theta: float) -> tuple[float, list[float]]:
            node = [self._node(j, theta, draw, cap, rate, w, k1, k2) for j in (0, 1)]
            tip = [k2 * max(node[j] - _SIDES[j] * d * theta, 0.0) for j in (0, 1)]
            stiff = p.bend_stiffness_Nmm_per_rad * (1.0 if theta >= 0.0 else p.notch_asymmetry)
            return d * (tip[0] - tip[1]) - stiff * theta, node

        lo, hi = -math.pi, math.pi
        r_lo, _ = residual(lo)
        r_hi, _ = residual(hi)
        side = 0
        theta, node = 0.0, list(self.node_mm)
        for _ in range(60):
            theta = hi - r_hi * (hi - lo) / (r_hi - r_lo) if r_hi != r_lo else 0.5 * (lo + hi)
            r, node = residual(theta)
            if abs(r) < 1e-9 or hi - lo < 1e-10:
                break
            if r > 0.0:
                lo, r_lo = theta, r
                if side == -1:
                    r_hi *= 0.5
                side = -1
            else:
                hi, r_hi = theta, r
                if side == 1:
                    r_lo *= 0.5
                side = 1
        return theta, node

    def knob_torque_Nm(self) -> float:
        p = self.p
        spring = return_spring_Nm(math.radians(self.knob_deg), p.return_preload_Nm,
                                  p.return_rate_Nm_per_rad, math.radians(p.return_width_deg))
        return self.drum_torque_Nm + spring + self.seal_Nm


class BeltBraidPlant:
    """Two knobs, four ropes, one braided shaft; implements :class:`simrig.plant.Plant`."""

    def __init__(self, knobs: Sequence[Any] | None = None, sheath_curvature_deg: float = 0.0
                 ) -> None:
        given = list(knobs) if knobs is not None else [{}, {}]
        if len(given) != 2:
            raise ValueError(f"beltbraid takes 2 knobs, got {len(given)}")
        self.params = tuple(knob_params(g, n) for g, n in zip(given, NOMINAL_KNOBS, strict=True))
        self.knobs = [_Knob(p) for p in self.params]
        self.sheath_curvature_deg = float(sheath_curvature_deg)
        p0 = self.params[0]
        self.braid = BraidRelays(p0.braid_onset_N, p0.braid_span_N, p0.braid_hold_N,
                                 p0.braid_slip_mm)
        self.shortening_mm = 0.0

    def reset(self) -> None:
        for k in self.knobs:
            k.reset()
        self.braid.reset()
        self.shortening_mm = 0.0

    def reshape(self, slack_delta_mm: Any = None, sheath_curvature_deg: float | None = None
                ) -> None:
        """Mid-run shape change: every rope's slack grows, or the anatomy bends the shaft."""
        if slack_delta_mm is not None:
            for k, (pos, neg) in zip(self.knobs, slack_delta_mm, strict=True):
                k.slack_mm = [k.slack_mm[0] + float(pos), k.slack_mm[1] + float(neg)]
        if sheath_curvature_deg is not None:
            self.sheath_curvature_deg = float(sheath_curvature_deg)

    def wrap_rad(self, p: KnobParams) -> float:
        return math.radians(p.sheath_wrap_deg + abs(self.sheath_curvature_deg))

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q = step_inputs(dt_s, knob_deg)
        for k, qk in zip(self.knobs, q, strict=True):
            k.step(dt_s, qk, self.shortening_mm, self.wrap_rad(k.p))
        load_N = sum(0.5 * (k.drum_N[j] + k.tip_N[j]) for k in self.knobs for j in (0, 1))
        p0 = self.params[0]
        self.shortening_mm = (self.braid.update(load_N)
                              + p0.braid_compliance_mm_per_N * load_N)
        tip = np.array([math.degrees(k.theta_rad) for k in self.knobs])
        torque = np.array([k.knob_torque_Nm() for k in self.knobs])
        return PlantStep(tip, torque)

    @property
    def tensions_N(self) -> NDArray[np.float64]:
        """Drum-side tension of every rope, [[A1, B1], [A2, B2]] (diagnostics)."""
        return np.array([k.drum_N for k in self.knobs])


def make_beltbraid_plant(knobs: Sequence[Any] | None = None, sheath_curvature_deg: float = 0.0
                         ) -> BeltBraidPlant:
    """``simrig.plants.beltbraid:make_beltbraid_plant`` for ``simrig.plant.load_plant``."""
    return BeltBraidPlant(knobs, sheath_curvature_deg)
