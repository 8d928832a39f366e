"""The helixbelt plant: a toothed-belt handle, helically routed tendons, a braided tip.

Per knob (one plane), quasi-static, solved each step by return mapping on the two lumen
contacts: first a trial with both contacts stuck (the tip holds its bend; the drum takes the
place where the belt's torque meets the tendons' pull, in closed form since the mesh deflection
is ~ sqrt(torque)); if a contact's tension difference exceeds its friction
(T_high <= T_low e^(mu Theta) + F0, Theta the helix wrap), that tendon slides and the tip's bend
is found by a bracketed false-position search on the knob angle it needs. The tendon that is not
pulling is dragged along by the tip (its distal tension at most the drag F0). The two planes
meet in the braid's stiffening with the total bend and in the helix's phase error at the tip.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantStep, step_inputs
from simrig.plants.helixbelt.laws import (
    friction_centroid,
    helix_length_factor,
    helix_wrap_rad,
    masing_moment_Nmm,
    mesh_deflection_rad,
)
from simrig.plants.helixbelt.params import NOMINAL_KNOBS, HelixKnobParams

_DEG = math.pi / 180.0
_STUCK_TOL_N = 1e-9
_Q_TOL_RAD = 1e-8
_MAX_BEND_RAD = 3.0
_KNOB_SPEED_SCALE_DEG_S = 2.0
"""Knob speed over which the shaft seal's friction builds up (tanh)."""


class _Plane:
    """One knob's belt, drum, two tendons and its plane of the braided section."""

    def __init__(self, p: HelixKnobParams, shaft_curvature_deg: float) -> None:
        self.p = p
        self.R = p.pulley_radius_mm
        self.a = p.tendon_offset_mm
        self.c = 0.5 * p.belt_clearance_deg * _DEG
        self.d_ref = p.belt_ref_deflection_deg * _DEG
        self.tau_ref = p.belt_ref_torque_Nm * 1000.0
        self.wrap_rad = 0.0
        self.gain = 1.0
        self.k1 = self.k2 = p.tendon_stiffness_N
        self._A = 0.0
        self.set_shape(shaft_curvature_deg, (0.0, 0.0))
        self.F0 = p.sheath_drag_N
        self.K = p.bend_stiffness_Nm_per_rad * 1000.0
        self.gamma = p.braid_stiffening_per_rad2
        self.Mf = p.braid_friction_Nm * 1000.0
        self.slip = p.braid_slip_deg * _DEG
        # mesh_deflection_rad inverted for the stuck trial, a quadratic in sqrt(T):
        # q = drum + c + d_ref sqrt(R T / tau_ref)
        self._B = self.d_ref * math.sqrt(self.R / self.tau_ref)
        self.reset()

    def set_shape(self, shaft_curvature_deg: float, slack_delta_mm: tuple[float, float]) -> None:
        """The shaft's extra curve (wrap: the helix keeps the tendons' length) and the tendons'
        slack relative to the built values; the state carries over."""
        p = self.p
        self.wrap_rad = helix_wrap_rad(p.sheath_length_m * 1000.0, p.helix_radius_mm,
                                       p.helix_pitch_mm,
                                       (p.sheath_wrap_deg + shaft_curvature_deg) * _DEG)
        self.gain = math.exp(p.sheath_friction * self.wrap_rad)
        shaft_mm = p.sheath_length_m * 1000.0 * helix_length_factor(p.helix_radius_mm,
                                                                    p.helix_pitch_mm)
        share = friction_centroid(p.sheath_friction * self.wrap_rad)
        self.k1 = p.tendon_stiffness_N / (p.free_length_m * 1000.0 + share * shaft_mm)
        self.k2 = p.tendon_stiffness_N / ((1.0 - share) * shaft_mm + p.bend_length_mm)
        self._A = 1.0 / (self.k1 * self.R)
        self.slack = (p.slack_pos_mm + slack_delta_mm[0], p.slack_neg_mm + slack_delta_mm[1])
        if min(self.slack) < 0.0:
            raise ValueError(f"helixbelt tendon slack must stay >= 0, got {self.slack} mm")

    def reset(self) -> None:
        self.bend = 0.0
        self.drum = 0.0
        self.z = [0.0, 0.0]  # tendon displacement at the contact, towards the handle (mm)
        self.t1 = [0.0, 0.0]  # proximal tensions (N)
        self.rev_bend = 0.0
        self.rev_moment = 0.0
        self.moment = 0.0
        self.direction = 0

    # -- laws --------------------------------------------------------------------------------
    def _braid(self, bend: float) -> float:
        return masing_moment_Nmm(bend, self.rev_bend, self.rev_moment, self.Mf, self.slip)

    def _section_moment(self, bend: float, other: float) -> float:
        stiffening = 1.0 + self.gamma * (bend * bend + other * other)
        return self.K * bend * stiffening + self._braid(bend)

    def _distal(self, k: int, bend: float) -> float:
        sign = 1.0 if k == 0 else -1.0
        return self.k2 * max(self.z[k] - sign * self.a * bend, 0.0)

    # -- the stuck trial ---------------------------------------------------------------------
    def _drum_stuck(self, q: float) -> tuple[float, float, float]:
        """Drum angle and the two proximal tensions with both contacts stuck."""
        free = min(q + self.c, max(q - self.c, self.drum))
        R = self.R
        if R * free - self.slack[0] - self.z[0] > 0.0:
            k, sign = 0, 1.0
        elif -R * free - self.slack[1] - self.z[1] > 0.0:
            k, sign = 1, -1.0
        else:
            return free, 0.0, 0.0
        C = (self.slack[k] + self.z[k]) / R + self.c - sign * q
        if C >= 0.0:  # taut only inside the clearance: the tendon stops the drum unloaded
            return sign * (self.slack[k] + self.z[k]) / R, 0.0, 0.0
        w = (-self._B + math.sqrt(self._B * self._B - 4.0 * self._A * C)) / (2.0 * self._A)
        T = w * w
        drum = q - sign * (self.c + self._B * w)
        return (drum, T, 0.0) if k == 0 else (drum, 0.0, T)

    # -- a sliding tendon --------------------------------------------------------------------
    def _knob_needed(self, bend: float, k: int, forward: bool, other: float) -> float | None:
        """Knob angle (signed towards tendon k) that holds ``bend`` with tendon k sliding;
        None where the tendon cannot hold the tip there (it would have to push)."""
        sign = 1.0 if k == 0 else -1.0
        o = 1 - k
        t2o = min(self.k2 * max(self.z[o] + sign * self.a * bend, 0.0), self.F0)
        t2 = sign * self._section_moment(bend, other) / self.a + t2o
        if t2 < 0.0:
            return None
        t1 = t2 * self.gain + self.F0 if forward else (t2 - self.F0) / self.gain
        if t1 <= 0.0:
            return None
        u = sign * self.a * bend + t2 / self.k2 + self.slack[k] + t1 / self.k1
        return u / self.R + mesh_deflection_rad(self.R * t1, self.c, self.d_ref, self.tau_ref)

    def _slide(self, q: float, k: int, forward: bool, other: float) -> None:
        sign = 1.0 if k == 0 else -1.0
        target = sign * q
        heading = int(sign) if forward else -int(sign)
        if heading != self.direction:
            self.rev_bend, self.rev_moment = self.bend, self.moment
            self.direction = heading

        def g(b_signed: float) -> float:
            need = self._knob_needed(sign * b_signed, k, forward, other)
            return -1.0 if need is None else need - target

        start = sign * self.bend
        step = 0.02 if forward else -0.02
        lo = hi = start
        g_start = g(start)
        glo = ghi = g_start
        # bracket: forward the bend grows, backward it shrinks (in the tendon's own sense)
        for _ in range(40):
            nxt = start + step
            gn = g(nxt)
            if forward:
                lo, glo, hi, ghi = hi, ghi, nxt, gn
                if gn > 0.0 or nxt >= _MAX_BEND_RAD:
                    break
            else:
                hi, ghi, lo, glo = lo, glo, nxt, gn
                if gn <= 0.0 or nxt <= -_MAX_BEND_RAD:
                    break
            start, step = nxt, 2.0 * step
        if not (glo <= 0.0 < ghi):
            b = hi if ghi <= 0.0 else lo
        else:
            side = 0
            b = lo
            for _ in range(60):
                if glo == -1.0 or ghi - glo <= 0.0:
                    b = 0.5 * (lo + hi)
                else:
                    b = lo - glo * (hi - lo) / (ghi - glo)
                    if not lo < b < hi:
                        b = 0.5 * (lo + hi)
                gb = g(b)
                if abs(gb) < _Q_TOL_RAD or hi - lo < 1e-10:
                    break
                if gb > 0.0:
                    hi, ghi = b, gb
                    if side == 1:
                        glo *= 0.5 if glo != -1.0 else 1.0
                    side = 1
                else:
                    lo, glo = b, gb
                    if side == -1:
                        ghi *= 0.5
                    side = -1
        self._settle(sign * b, k, forward, q, other)

    def _settle(self, bend: float, k: int, forward: bool, q: float, other: float) -> None:
        sign = 1.0 if k == 0 else -1.0
        o = 1 - k
        self.bend = bend
        self.moment = self._braid(bend)
        t2o = self.k2 * max(self.z[o] + sign * self.a * bend, 0.0)
        if t2o > self.F0:
            self.z[o] = self.F0 / self.k2 - sign * self.a * bend
            t2o = self.F0
        t2 = max(sign * self._section_moment(bend, other) / self.a + t2o, 0.0)
        t1 = max(t2 * self.gain + self.F0 if forward else (t2 - self.F0) / self.gain, 0.0)
        self.z[k] = sign * self.a * bend + t2 / self.k2
        self.t1 = [t1, 0.0] if k == 0 else [0.0, t1]
        if t1 > 0.0:
            self.drum = sign * (self.z[k] + self.slack[k] + t1 / self.k1) / self.R
        else:
            self.drum = min(q + self.c, max(q - self.c, self.drum))

    def _gather_slack(self) -> None:
        """A tendon slack beyond its contact holds no tension there: its slack is counted on the
        handle side (the contact sits where the distal end is), so that it engages when its
        whole length is taken up, not when its proximal part alone is."""
        a, bend = self.a, self.bend
        if self.z[0] < a * bend:
            self.z[0] = a * bend
        if self.z[1] < -a * bend:
            self.z[1] = -a * bend

    # -- one step ----------------------------------------------------------------------------
    def step(self, q_deg: float, other_bend: float) -> float:
        """Advance to knob ``q_deg``; returns the belt torque at the knob (N mm)."""
        q = q_deg * _DEG
        drum, t1p, t1n = self._drum_stuck(q)
        t1 = (t1p, t1n)
        excess = 0.0
        slide: tuple[int, bool] | None = None
        for k in (0, 1):
            t2 = self._distal(k, self.bend)
            fwd = t1[k] - (t2 * self.gain + self.F0)
            back = t2 - (t1[k] * self.gain + self.F0)
            if fwd > max(excess, _STUCK_TOL_N) and t1[k] > 0.0:
                excess, slide = fwd, (k, True)
            elif back > max(excess, _STUCK_TOL_N):
                excess, slide = back, (k, False)
        if slide is None:
            self.drum, self.t1 = drum, [t1p, t1n]
        else:
            self._slide(q, slide[0], slide[1], other_bend)
        self._gather_slack()
        return self.R * (self.t1[0] - self.t1[1])


class HelixBeltPlant:
    """Two knobs on toothed belts, helically routed steel tendons, a braided bending section."""

    def __init__(self, knobs: Sequence[HelixKnobParams], sheath_curvature_deg: float = 0.0
                 ) -> None:
        if len(knobs) != 2:
            raise ValueError(f"the helixbelt plant has two knobs, got {len(knobs)}")
        if not (math.isfinite(sheath_curvature_deg) and sheath_curvature_deg >= 0.0):
            raise ValueError(f"sheath_curvature_deg must be finite and >= 0, "
                             f"got {sheath_curvature_deg!r}")
        self.knobs = tuple(knobs)
        self.sheath_curvature_deg = sheath_curvature_deg
        self.planes = [_Plane(p, sheath_curvature_deg) for p in knobs]
        e1 = knobs[0].plane_error_deg * _DEG
        e2 = knobs[1].plane_error_deg * _DEG
        # tip (AP, RL) from the two planes' bends: plane 1 along (cos e1, sin e1),
        # plane 2 along (-sin e2, cos e2)
        self._mix = ((math.cos(e1), -math.sin(e2)), (math.sin(e1), math.cos(e2)))
        self._seal = (knobs[0].handle_friction_Nm, knobs[1].handle_friction_Nm)
        self._last_q = [0.0, 0.0]

    def reshape(self, sheath_curvature_deg: float | None = None,
                slack_delta_mm: Sequence[tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
                ) -> None:
        """Change the shaft's shape now (``simrig.scenario``): its extra curve, and per knob the
        tendons' slack (pos, neg) relative to the built values; the state carries over."""
        if sheath_curvature_deg is not None:
            if not (math.isfinite(sheath_curvature_deg) and sheath_curvature_deg >= 0.0):
                raise ValueError(f"sheath_curvature_deg must be finite and >= 0, "
                                 f"got {sheath_curvature_deg!r}")
            self.sheath_curvature_deg = float(sheath_curvature_deg)
        if len(slack_delta_mm) != 2:
            raise ValueError(f"slack_delta_mm must list 2 knobs, got {len(slack_delta_mm)}")
        for plane, (d_pos, d_neg) in zip(self.planes, slack_delta_mm, strict=True):
            plane.set_shape(self.sheath_curvature_deg, (float(d_pos), float(d_neg)))

    def reset(self) -> None:
        for plane in self.planes:
            plane.reset()
        self._last_q = [0.0, 0.0]

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q0, q1 = step_inputs(dt_s, knob_deg)
        p0, p1 = self.planes
        tau0 = p0.step(q0, p1.bend)
        tau1 = p1.step(q1, p0.bend)
        torques = []
        for i, (q, tau) in enumerate(((q0, tau0), (q1, tau1))):
            speed = (q - self._last_q[i]) / dt_s if dt_s > 0.0 else 0.0
            seal = self._seal[i] * math.tanh(speed / _KNOB_SPEED_SCALE_DEG_S)
            torques.append(tau / 1000.0 + seal)
        self._last_q = [q0, q1]
        (m00, m01), (m10, m11) = self._mix
        b0, b1 = p0.bend / _DEG, p1.bend / _DEG
        tip = np.array([m00 * b0 + m01 * b1, m10 * b0 + m11 * b1])
        return PlantStep(tip, np.array(torques))


def make_helixbelt_plant(knobs: Sequence[dict[str, Any] | HelixKnobParams] | None = None,
                         sheath_curvature_deg: float = 0.0) -> HelixBeltPlant:
    """The helixbelt plant; ``knobs`` overrides per knob (dicts of :class:`HelixKnobParams`
    fields, or the dataclasses)."""
    chosen = NOMINAL_KNOBS if knobs is None else knobs
    if len(chosen) != 2:
        raise ValueError(f"knobs must list 2 knobs, got {len(chosen)}")
    built = []
    for k, nominal in zip(chosen, NOMINAL_KNOBS, strict=True):
        if isinstance(k, HelixKnobParams):
            built.append(k)
            continue
        unknown = set(k) - set(asdict(nominal))
        if unknown:
            raise ValueError(f"unknown helixbelt knob constants: {', '.join(sorted(unknown))}")
        built.append(HelixKnobParams(**{**asdict(nominal), **k}))
    return HelixBeltPlant(built, sheath_curvature_deg)
