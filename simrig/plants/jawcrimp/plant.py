"""The jawcrimp plant: a quasi-static Newton step per knob over drum, tip and shaft.

Per knob the unknowns are the drum angle (behind the jaw coupling), the tip angle and the
shaft's shortening; both ropes of the pair go over their own friction node (closed form in
:func:`laws.friction_node`). The other knob enters through the shaft's common load (its last
solved value) and the section's stiffening with the total bend.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.jawcrimp.laws import (
    crimp_creep_rate_mm_s,
    friction_node,
    heart_pulse,
    jaw_torque_Nmm,
    shaft_shortening_mm,
)
from simrig.plants.jawcrimp.params import JawCrimpKnob, knobs_from, node_friction

_NEWTON_ITERATIONS = 12
_TOL_NMM = 1e-6
_TOL_MM = 1e-9


class _Knob:
    """Constants of one knob in the units the step uses (mm, N, N mm, rad)."""

    def __init__(self, k: JawCrimpKnob, curvature_deg: float,
                 slack_delta_mm: tuple[float, float] = (0.0, 0.0)) -> None:
        self.r = k.pulley_radius_mm
        self.a = k.tendon_offset_mm
        self.play = math.radians(k.jaw_play_deg)
        self.play_k = 1000.0 * k.jaw_play_stiffness_Nm_per_rad
        self.jaw_rad = math.radians(k.jaw_twist_deg)
        self.jaw_Nmm = 1000.0 * k.jaw_torque_Nm
        proximal_mm = 1000.0 * (k.free_length_m + k.node_share * k.sheath_length_m)
        distal_mm = 1000.0 * (1.0 - k.node_share) * k.sheath_length_m
        self.k1 = k.tendon_stiffness_N / proximal_mm
        self.k2 = k.tendon_stiffness_N / distal_mm
        self.share = node_friction(k, curvature_deg)
        self.drag = k.sheath_drag_N
        self.slack = (k.slack_pos_mm + slack_delta_mm[0], k.slack_neg_mm + slack_delta_mm[1])
        self.bend = k.bend_stiffness_Nmm_per_rad
        self.stiffening = k.bend_stiffening_per_rad2
        self.seal = k.handle_friction_Nm
        self.seal_speed = math.radians(k.handle_speed_deg_s)
        self.inertia = k.idler_inertia_kgm2
        self.tissue = k.tissue_moment_Nmm
        self.tissue_rad = math.radians(k.tissue_angle_deg)
        self.heart = k.heart_moment_Nmm
        self.heart_phase = k.heart_phase_deg
        self.creep = (k.crimp_creep_mm_per_s, k.crimp_creep_load_N, k.crimp_creep_exponent,
                      k.crimp_hardening_mm)


class JawCrimpPlant:
    """Two knobs, each through a jaw coupling to a drum, ropes over idlers and a friction
    node into a shaft that shortens under load, crimped to a pull ring that creeps; the tip
    pushed by the heart."""

    def __init__(self, knobs: tuple[JawCrimpKnob, JawCrimpKnob], curvature_deg: float = 0.0
                 ) -> None:
        self.knobs = knobs
        self.sheath_curvature_deg = curvature_deg
        self._slack_delta_mm = [[0.0, 0.0], [0.0, 0.0]]
        self._k = [_Knob(k, curvature_deg) for k in knobs]
        self._gap_mm = 0.5 * (knobs[0].shaft_gap_mm + knobs[1].shaft_gap_mm)
        self._gap_load_N = 0.5 * (knobs[0].shaft_gap_load_N + knobs[1].shaft_gap_load_N)
        self._shaft_k = 0.5 * (knobs[0].shaft_stiffness_N_per_mm
                               + knobs[1].shaft_stiffness_N_per_mm)
        self._heart_hz = knobs[0].heart_rate_hz
        self.reset()

    def reset(self) -> None:
        self.t_s = 0.0
        self._drum = [0.0, 0.0]
        self._tip = [0.0, 0.0]
        self._shorten = [0.0, 0.0]
        self._load = [0.0, 0.0]
        """Each knob's share of the shaft's compressive load (N)."""
        self._node = [[0.0, 0.0], [0.0, 0.0]]
        self._crept = [[0.0, 0.0], [0.0, 0.0]]
        self._tensions = [[0.0, 0.0], [0.0, 0.0]]
        self._q_rad = [0.0, 0.0]
        self._w_rad_s = [0.0, 0.0]

    def reshape(self, **changes: Any) -> None:
        """A shape change mid-run (kept through ``reset``): ``slack_delta_mm`` ((pos, neg) per
        knob, added to the ropes' slack) or ``sheath_curvature_deg`` (the lumens' added
        curve: more friction at the node)."""
        for name, value in changes.items():
            if name == "slack_delta_mm":
                try:
                    delta = [[float(value[i][j]) for j in (0, 1)] for i in (0, 1)]
                except (TypeError, ValueError, IndexError):
                    raise PlantLoadError("slack_delta_mm must be ((pos, neg), (pos, neg)) mm"
                                         ) from None
                for i in (0, 1):
                    for j in (0, 1):
                        self._slack_delta_mm[i][j] += delta[i][j]
            elif name == "sheath_curvature_deg":
                knobs_from(self.knobs, float(value))  # the same checks as at build
                self.sheath_curvature_deg = float(value)
            else:
                raise PlantLoadError(f"jawcrimp cannot reshape {name}")
        self._k = [_Knob(k, self.sheath_curvature_deg,
                         (self._slack_delta_mm[i][0], self._slack_delta_mm[i][1]))
                   for i, k in enumerate(self.knobs)]

    @property
    def shortening_mm(self) -> float:
        """The shaft's current axial shortening (mm)."""
        return self._shorten[1]

    @property
    def crept_mm(self) -> list[list[float]]:
        """Slip of each rope out of its pull ring so far (mm), [knob][positive, negative]."""
        return [list(c) for c in self._crept]

    def tensions_N(self) -> list[list[float]]:
        """Distal rope tensions (N), [knob][positive, negative]."""
        return [list(t) for t in self._tensions]

    def _residuals(self, i: int, q: float, d: float, th: float, dl: float, other_load: float,
                   moment: float) -> tuple[list[float], list[list[float]], tuple[Any, ...]]:
        c = self._k[i]
        r, a = c.r, c.a
        x0 = self._node[i]
        cr = self._crept[i]
        na = friction_node(r * d - c.slack[0], a * th + dl + cr[0], x0[0], c.k1, c.k2,
                           c.share, c.drag)
        nb = friction_node(-r * d - c.slack[1], -a * th + dl + cr[1], x0[1], c.k1, c.k2,
                           c.share, c.drag)
        jaw, jaw_k = jaw_torque_Nmm(q - d, c.play, c.play_k, c.jaw_rad, c.jaw_Nmm)
        th_o = self._tip[1 - i]
        stiff = c.bend * (1.0 + c.stiffening * (th * th + th_o * th_o))
        stiff_d = c.bend * (1.0 + c.stiffening * (3.0 * th * th + th_o * th_o))
        push = math.tanh(th / c.tissue_rad)
        tissue = c.tissue * push
        tissue_d = c.tissue / c.tissue_rad * (1.0 - push * push)
        load = 0.5 * (na[0] + na[1] + nb[0] + nb[1])
        short, comp = shaft_shortening_mm(load + other_load, self._gap_mm, self._gap_load_N,
                                          self._shaft_k)
        res = [jaw - r * (na[0] - nb[0]), a * (na[1] - nb[1]) - stiff * th - tissue - moment,
               dl - short]
        # slopes of the tensions in (d, th, dl): u_a = r d, u_b = -r d, y_a = a th, y_b = -a th
        jac1 = [-jaw_k - r * (r * na[3] + r * nb[3]), -r * (a * na[4] + a * nb[4]),
                -r * (na[4] - nb[4])]
        jac2 = [a * (r * na[5] + r * nb[5]), a * (a * na[6] + a * nb[6]) - stiff_d - tissue_d,
                a * (na[6] - nb[6])]
        dload = [0.5 * r * (na[3] + na[5] - nb[3] - nb[5]),
                 0.5 * a * (na[4] + na[6] - nb[4] - nb[6]),
                 0.5 * (na[4] + na[6] + nb[4] + nb[6])]
        jac3 = [-comp * dload[0], -comp * dload[1], 1.0 - comp * dload[2]]
        return res, [jac1, jac2, jac3], (na, nb, jaw, load)

    def _solve(self, i: int, q: float, other_load: float, moment: float
               ) -> tuple[float, float, float, tuple[Any, ...]]:
        d, th, dl = self._drum[i] + (q - self._q_rad[i]), self._tip[i], self._shorten[1 - i]
        res, jac, parts = self._residuals(i, q, d, th, dl, other_load, moment)
        for _ in range(_NEWTON_ITERATIONS):
            if abs(res[0]) < _TOL_NMM and abs(res[1]) < _TOL_NMM and abs(res[2]) < _TOL_MM:
                break
            step = _solve3(jac, res)
            if step is None:
                break
            scale = 1.0
            norm = abs(res[0]) + abs(res[1]) + 100.0 * abs(res[2])
            for _ in range(6):
                nd, nth, ndl = d - scale * step[0], th - scale * step[1], dl - scale * step[2]
                nres, njac, nparts = self._residuals(i, q, nd, nth, ndl, other_load, moment)
                if abs(nres[0]) + abs(nres[1]) + 100.0 * abs(nres[2]) < norm:
                    break
                scale *= 0.5
            d, th, dl, res, jac, parts = nd, nth, ndl, nres, njac, nparts
        return d, th, dl, parts

    def step(self, dt_s: float, knob_deg: Any) -> PlantStep:
        q_deg = step_inputs(dt_s, knob_deg)
        self.t_s += dt_s
        torque = [0.0, 0.0]
        for i in (0, 1):
            c = self._k[i]
            q = math.radians(q_deg[i])
            moment = c.heart * heart_pulse(self.t_s, self._heart_hz, c.heart_phase)
            d, th, dl, (na, nb, jaw, load) = self._solve(i, q, self._load[1 - i], moment)
            self._drum[i], self._tip[i], self._shorten[i], self._load[i] = d, th, dl, load
            self._node[i] = [na[2], nb[2]]
            self._tensions[i] = [na[1], nb[1]]
            w = (q - self._q_rad[i]) / dt_s if dt_s > 0.0 else self._w_rad_s[i]
            alpha = (w - self._w_rad_s[i]) / dt_s if dt_s > 0.0 else 0.0
            self._q_rad[i], self._w_rad_s[i] = q, w
            torque[i] = (0.001 * jaw + c.seal * math.tanh(w / c.seal_speed)
                         + c.inertia * alpha)
            cr = self._crept[i]
            for j, tension in enumerate((na[1], nb[1])):
                cr[j] += dt_s * crimp_creep_rate_mm_s(tension, cr[j], *c.creep)
        return PlantStep(np.array([math.degrees(self._tip[0]), math.degrees(self._tip[1])]),
                         np.array(torque))


def _solve3(m: list[list[float]], b: list[float]) -> list[float] | None:
    """m x = b for a 3x3 system by Cramer's rule (None when singular)."""
    (a, b1, c), (d, e, f), (g, h, k) = m
    co0, co1, co2 = e * k - f * h, f * g - d * k, d * h - e * g
    det = a * co0 + b1 * co1 + c * co2
    if det == 0.0 or not math.isfinite(det):
        return None
    r0, r1, r2 = b
    x0 = (r0 * co0 + r1 * (c * h - b1 * k) + r2 * (b1 * f - c * e)) / det
    x1 = (r0 * co1 + r1 * (a * k - c * g) + r2 * (c * d - a * f)) / det
    x2 = (r0 * co2 + r1 * (b1 * g - a * h) + r2 * (a * e - b1 * d)) / det
    return [x0, x1, x2]


def make_jawcrimp_plant(knobs: Sequence[Mapping[str, Any] | JawCrimpKnob] | None = None,
                        sheath_curvature_deg: float = 0.0) -> JawCrimpPlant:
    """The jawcrimp plant (``simrig.plants.jawcrimp:make_jawcrimp_plant``); ``knobs`` overrides
    each knob's constants by name; ``sheath_curvature_deg`` adds a curve to both lumens."""
    return JawCrimpPlant(knobs_from(knobs, sheath_curvature_deg), sheath_curvature_deg)
