"""The screwrod plant: a lead-screw handle, UHMWPE tendons and a Kirchhoff-rod tip at a wall.

Per knob, one quasi-static equilibrium per step: unknowns are the two tendons' displacements at
their sheath contacts and the tip angle; the residuals are the contacts' force balances and the
tip's moment balance. They are solved by Newton on a 3x3 system eliminated by hand (the two
contacts couple only through the tip), the Iwan contacts by return mapping from the step's start
state, so the step is implicit and stable at any time step. Afterwards the tendons creep
(explicit, minutes-slow) and the collar's thread friction gives the knob torque.

Cross-coupling of the knobs is physical: each tendon runs through the whole bending section, so
both planes' bends add to its wrap (friction grows with the other knob's bend). The wrap uses
the previous step's bends (a lag of one step, far below the dynamics here).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.screwrod.params import (
    NOMINAL_KNOBS,
    NOMINAL_WALL,
    ScrewRodKnobParams,
    knob_params,
    screw_factors,
    wall_params,
)
from simrig.plants.screwrod.rod import BendingSection
from simrig.plants.screwrod.tendon import TendonState, fibre, iwan

_SIGNS = (1, -1)
_MAX_ITER = 25
_TOL_N = 1e-7


class _Knob:
    """One knob's constants in SI, its bending plane and its tendons' states."""

    def __init__(self, p: ScrewRodKnobParams, section: BendingSection) -> None:
        self.p = p
        self.section = section
        self.lead_m_per_rad = p.screw_lead_mm * 1e-3 / (2.0 * math.pi)
        self.offset_m = p.tendon_offset_mm * 1e-3
        self.toe_m = p.toe_mm * 1e-3
        half_sheath = 0.5 * p.sheath_length_m
        self.k_prox = p.tendon_stiffness_N / (p.free_length_m + half_sheath)
        self.k_dist = p.tendon_stiffness_N / (half_sheath + p.bend_length_mm * 1e-3)
        self.presliding_m = p.presliding_mm * 1e-3
        self.screw_mean, self.screw_half = screw_factors(p)
        self.slack_delta_m = [0.0, 0.0]
        self.reset()

    def reset(self) -> None:
        self.tendons = [TendonState(), TendonState()]
        self.theta_rad = 0.0
        self.thread_z = 0.0
        self.knob_deg = 0.0
        self.tension_prox_N = [0.0, 0.0]

    def solve(self, knob_deg: float, wrap_rad: float) -> None:
        """Equilibrium at the new knob angle (Newton, eliminated 3x3)."""
        p = self.p
        u = self.lead_m_per_rad * math.radians(knob_deg)
        # the contact's capacity per newton of mean tension: at full slip the tensions on its
        # two sides then stand in the capstan ratio exp(mu x wrap) however large the wrap
        grip = 2.0 * math.tanh(0.5 * p.sheath_friction * wrap_rad)
        r = self.offset_m
        w = [t.contact_m for t in self.tendons]
        theta = self.theta_rad
        for _ in range(_MAX_ITER):
            res, jww, jwt, cpl, tp, slips = [], [], [], [], [], []
            td_net = 0.0
            for j, sign in enumerate(_SIGNS):
                st = self.tendons[j]
                ep = sign * u - p.slack_m(sign) - self.slack_delta_m[j] - st.creep_m - w[j]
                t_p, k_p = fibre(ep, self.k_prox, self.toe_m)
                t_d, k_d = fibre(w[j] - sign * r * theta, self.k_dist, 0.0)
                s_sum, s_slope, z = iwan(st, w[j], self.presliding_m)
                normal = p.sheath_drag_N + 0.5 * grip * (t_p + t_d)
                res.append(t_p - t_d - normal * s_sum)
                d_normal_w = 0.5 * grip * (k_d - k_p)
                jww.append(min(-k_p - k_d - normal * s_slope - s_sum * d_normal_w,
                               -1e-6 * self.k_dist))
                jwt.append(sign * r * k_d * (1.0 + 0.5 * grip * s_sum))
                cpl.append(r * sign * k_d)
                tp.append(t_p)
                slips.append(z)
                td_net += sign * t_d
            m_rod, k_rod = self.section.moment(theta)
            res_t = r * td_net - m_rod
            jtt = -k_rod - r * (abs(cpl[0]) + abs(cpl[1]))
            num = -res_t + sum(cpl[j] * res[j] / jww[j] for j in range(2))
            den = jtt - sum(cpl[j] * jwt[j] / jww[j] for j in range(2))
            d_theta = num / den
            for j in range(2):
                w[j] -= (res[j] + jwt[j] * d_theta) / jww[j]
            theta += d_theta
            if abs(res[0]) + abs(res[1]) < _TOL_N and abs(res_t) < _TOL_N * r:
                break
        for j in range(2):
            st = self.tendons[j]
            _, _, z = iwan(st, w[j], self.presliding_m)
            self.tendons[j] = TendonState(w[j], z, st.creep_m)
        self.theta_rad = theta
        self.tension_prox_N = tp

    def creep(self, dt_s: float) -> None:
        """UHMWPE primary creep: rate ~ (T / T_ref)^2, saturating at the creep limit."""
        p = self.p
        limit = p.creep_limit_mm * 1e-3
        for j, st in enumerate(self.tendons):
            load = self.tension_prox_N[j] / p.creep_reference_N
            rate = load * load / p.creep_time_s
            st.creep_m += (limit - st.creep_m) * (1.0 - math.exp(-rate * dt_s))

    def torque_Nm(self, knob_deg: float) -> float:
        """Collar torque: thread friction by power direction, plus the seal."""
        p = self.p
        self.thread_z = min(1.0, max(-1.0, self.thread_z + (knob_deg - self.knob_deg)
                                     / p.handle_presliding_deg))
        self.knob_deg = knob_deg
        t_pos, t_neg = self.tension_prox_N
        return (self.lead_m_per_rad * (self.screw_mean * (t_pos - t_neg)
                                       + self.screw_half * self.thread_z * (t_pos + t_neg))
                + p.handle_friction_Nm * self.thread_z)


def _section(p: ScrewRodKnobParams, gap_m: float | None, wall_N_per_m: float
             ) -> BendingSection:
    return BendingSection(p.bend_length_mm * 1e-3, p.bend_stiffness_Nm_per_rad,
                          math.radians(p.bend_limit_deg), p.link_stiffness_Nm_per_rad,
                          gap_m, wall_N_per_m)


class ScrewRodPlant:
    """Two knobs on lead-screw collars, UHMWPE tendons, a rod tip that meets a wall
    (anteriorly, knob 1 positive)."""

    def __init__(self, knobs: tuple[ScrewRodKnobParams, ScrewRodKnobParams],
                 wall_gap_mm: float, wall_stiffness_N_per_mm: float,
                 sheath_curvature_deg: float) -> None:
        wall = wall_params(wall_gap_mm, wall_stiffness_N_per_mm)
        sections = (_section(knobs[0], wall.wall_gap_mm * 1e-3,
                             wall.wall_stiffness_N_per_mm * 1e3),
                    _section(knobs[1], None, 0.0))
        self.knobs = [_Knob(p, s) for p, s in zip(knobs, sections, strict=True)]
        self.sheath_curvature_deg = 0.0
        self.reshape(sheath_curvature_deg=sheath_curvature_deg)

    def reset(self) -> None:
        """Straight and unloaded, tendons as assembled (no creep, no slack change kept
        besides a reshape's)."""
        for k in self.knobs:
            k.reset()

    def reshape(self, **changes: Any) -> None:
        """``sheath_curvature_deg`` (extra sheath turning) and ``slack_delta_mm`` (per knob,
        (pos, neg) extra slack in mm); other names are refused."""
        for name, value in changes.items():
            if name == "sheath_curvature_deg":
                v = float(value)
                if not (math.isfinite(v) and v >= 0.0):
                    raise PlantLoadError(f"screwrod: sheath_curvature_deg must be finite and "
                                         f">= 0, got {value!r}")
                self.sheath_curvature_deg = v
            elif name == "slack_delta_mm":
                try:
                    pairs = [(float(a), float(b)) for a, b in value]
                except (TypeError, ValueError):
                    pairs = []
                if len(pairs) != 2 or not all(math.isfinite(x) for pr in pairs for x in pr):
                    raise PlantLoadError("screwrod: slack_delta_mm must be two (pos, neg) "
                                         f"pairs of finite mm, got {value!r}")
                for k, (a, b) in zip(self.knobs, pairs, strict=True):
                    k.slack_delta_m = [k.slack_delta_m[0] + a * 1e-3,
                                       k.slack_delta_m[1] + b * 1e-3]
            else:
                raise PlantLoadError(f"screwrod: cannot reshape {name!r}")

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q = step_inputs(dt_s, knob_deg)
        k0, k1 = self.knobs
        curve = math.radians(self.sheath_curvature_deg)
        bends = (abs(k0.theta_rad), abs(k1.theta_rad))
        torques = []
        for i, k in enumerate(self.knobs):
            wrap = math.radians(k.p.sheath_wrap_deg) + curve + bends[0] + bends[1]
            k.solve(q[i], wrap)
            k.creep(dt_s)
            torques.append(k.torque_Nm(q[i]))
        tip = np.array([math.degrees(k0.theta_rad), math.degrees(k1.theta_rad)])
        return PlantStep(tip, np.array(torques))

    @property
    def tension_prox_N(self) -> NDArray[np.float64]:
        """Handle-side tensions, [knob][pos, neg] (diagnostics)."""
        return np.array([k.tension_prox_N for k in self.knobs])

    @property
    def creep_mm(self) -> NDArray[np.float64]:
        """Plastic elongation so far, [knob][pos, neg] (diagnostics)."""
        return np.array([[t.creep_m * 1e3 for t in k.tendons] for k in self.knobs])


def make_screwrod_plant(knobs: list[dict[str, Any]] | None = None,
                        wall_gap_mm: float = NOMINAL_WALL.wall_gap_mm,
                        wall_stiffness_N_per_mm: float = NOMINAL_WALL.wall_stiffness_N_per_mm,
                        sheath_curvature_deg: float = 0.0) -> ScrewRodPlant:
    """Factory for ``simrig.plants.screwrod:make_screwrod_plant`` (family ``knobs`` overrides)."""
    if knobs is None:
        pair = NOMINAL_KNOBS
    else:
        if not isinstance(knobs, (list, tuple)) or len(knobs) != 2:
            raise PlantLoadError(f"screwrod: knobs must be a list of 2 dicts, got {knobs!r}")
        pair = (knob_params(knobs[0]), knob_params(knobs[1]))
    return ScrewRodPlant(pair, wall_gap_mm, wall_stiffness_N_per_mm, sheath_curvature_deg)
