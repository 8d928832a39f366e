"""The warmgear plant: a spur-gear handle, a warming shaft and a fluid-filled sheath.

Per knob (one plane): the knob's pinion drives the drum gear through a compliant mesh with play
(stiffness and flank loss follow the mesh position); the drum pulls two wire-rope tendons whose
slack shrinks as the shaft warms to body temperature; each tendon rubs its lumen through a film
that load squeezes out and sliding drags back in (friction between a full-film and a boundary
level, plus the film's viscous shear); the section bends against a stiffness that differs
between the planes, stiffens with the total bend and softens as it warms. Quasi-static: per
plane the drum and the tip are each a stick-or-slide problem, solved alternately to agreement.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.warmgear.laws import (
    film_after,
    mesh_loss,
    mesh_phase,
    mesh_stiffness,
    play_deflection,
    root_decreasing,
    shaft_temperature_C,
    viscosity_factor,
)
from simrig.plants.warmgear.params import ShaftParams, WarmGearKnobParams, knob_params

DEG = math.pi / 180.0
MAX_FRICTION_RATIO = 0.95
"""Friction x wrap is kept below 1: a lumped contact with more would lock itself."""
_SWEEPS = 8


class _Plane:
    """One knob's plane: its constants in solver units (N, mm, rad) and its state."""

    def __init__(self, p: WarmGearKnobParams) -> None:
        self.p = p
        self.ratio = p.pinion_teeth / p.drum_teeth
        self.r = p.pulley_radius_mm
        self.rho = p.tendon_offset_mm
        to_contact_mm = 1000.0 * (p.free_length_m + p.contact_position * p.sheath_length_m)
        self.k_handle = p.tendon_stiffness_N / to_contact_mm
        self.k_shaft = p.tendon_stiffness_N / (1000.0 * (1.0 - p.contact_position)
                                               * p.sheath_length_m)
        self.shrink_per_K = p.thermal_mismatch_per_K * p.inserted_share * p.sheath_length_m * 1e3
        self.bend_Nmm = p.bend_stiffness_Nm_per_rad * 1000.0
        self.extra_slack = [0.0, 0.0]
        self.reset()

    def reset(self) -> None:
        self.drum_deg = 0.0
        self.tip_rad = 0.0
        self.knob_deg = 0.0
        self.contact_mm = [0.0, 0.0]
        """Each tendon's travel towards the drum at the shaft's contact (pos, neg)."""
        self.film_shaft = [1.0, 1.0]
        self.film_tip = [1.0, 1.0]
        self.tension_N = [0.0, 0.0]
        """Proximal (drum-side) tension of each tendon."""
        self.mesh_Nmm = 0.0


def _tendon(draw: float, take: float, u0: float, k1: float, k2: float, mu_w: float,
            drag: float, visc: float) -> tuple[float, float, float, float, float, float, float]:
    """One tendon with the shaft's contact between its handle part (stiffness ``k1``, slack
    already taken off ``draw``) and its shaft part (``k2``, to the section's take-up ``take``):
    the contact sticks while the tension step across it is within its friction (film share x
    wrap x shaft-side tension + drag), else slides against the film's shear ``visc`` (N/mm at
    this step). Returns the drum-side tension, the contact's travel, the shaft-side tension,
    and the slopes of the drum-side tension per mm of draw and of take-up, and of the
    shaft-side tension per mm of take-up and of draw."""
    t1 = k1 * (draw - u0) if draw > u0 else 0.0
    t2 = k2 * (u0 - take) if u0 > take else 0.0
    diff = t1 - t2
    if abs(diff) <= mu_w * t2 + drag:
        return (t1, u0, t2, (k1 if draw > u0 else 0.0), 0.0, (-k2 if u0 > take else 0.0), 0.0)
    s = 1.0 if diff > 0.0 else -1.0
    k2s = k2 * (1.0 + s * mu_w)
    rhs = visc * u0 - s * drag
    den = k1 + k2s + visc
    u = (k1 * draw + k2s * take + rhs) / den
    if take < u < draw:
        return (k1 * (draw - u), u, k2 * (u - take), k1 * (1.0 - k1 / den), -k1 * k2s / den,
                k2 * (k2s / den - 1.0), k2 * k1 / den)
    u = (k1 * draw + rhs) / (k1 + visc)
    if u <= take and u < draw:
        return k1 * (draw - u), u, 0.0, k1 * (1.0 - k1 / (k1 + visc)), 0.0, 0.0, 0.0
    den = k2s + visc
    u = (k2s * take + rhs) / den
    if u >= draw and u > take:
        return 0.0, u, k2 * (u - take), 0.0, 0.0, k2 * (k2s / den - 1.0), 0.0
    return 0.0, rhs / visc, 0.0, 0.0, 0.0, 0.0, 0.0


class WarmGearPlant:
    """Two planes sharing one shaft (temperature, wrap) and one bending section."""

    def __init__(self, knobs: Sequence[WarmGearKnobParams], shaft: ShaftParams | None = None,
                 sheath_curvature_deg: float = 0.0) -> None:
        self.knobs = tuple(knobs)
        self.shaft = shaft or ShaftParams()
        self.planes = [_Plane(p) for p in self.knobs]
        self.sheath_curvature_deg = 0.0
        self._set_curvature(sheath_curvature_deg)
        self.reset()

    def _set_curvature(self, sheath_curvature_deg: float) -> None:
        if not (math.isfinite(sheath_curvature_deg) and sheath_curvature_deg >= 0.0):
            raise PlantLoadError(f"sheath_curvature_deg must be >= 0, got {sheath_curvature_deg!r}")
        self.sheath_curvature_deg = float(sheath_curvature_deg)

    def reset(self) -> None:
        """Straight, unloaded and just inserted (at room temperature)."""
        self.t_s = 0.0
        for plane in self.planes:
            plane.reset()

    def reshape(self, **changes: Any) -> None:
        """Mid-run changes: ``slack_delta_mm=((pos, neg), (pos, neg))`` (mm added to each
        tendon's slack) and ``sheath_curvature_deg`` (a bend of the shaft added to every wrap)."""
        for name, value in changes.items():
            if name == "slack_delta_mm":
                for plane, (d_pos, d_neg) in zip(self.planes, value, strict=True):
                    plane.extra_slack[0] += float(d_pos)
                    plane.extra_slack[1] += float(d_neg)
            elif name == "sheath_curvature_deg":
                self._set_curvature(float(value))
            else:
                raise PlantLoadError(f"cannot reshape {name}; known: slack_delta_mm, "
                                     "sheath_curvature_deg")

    @property
    def temperature_C(self) -> float:
        s = self.shaft
        return shaft_temperature_C(self.t_s, s.room_C, s.body_C, s.warm_time_s)

    def tensions_N(self) -> NDArray[np.float64]:
        """Proximal tendon tensions ``[[pos, neg], [pos, neg]]`` after the last step."""
        return np.array([pl.tension_N for pl in self.planes])

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q = step_inputs(dt_s, knob_deg)
        self.t_s += dt_s
        s = self.shaft
        temp = shaft_temperature_C(self.t_s, s.room_C, s.body_C, s.warm_time_s)
        warm_K = temp - s.room_C
        visc = viscosity_factor(temp, s.room_C)
        a1, a2 = self.planes[0].tip_rad, self.planes[1].tip_rad
        bend_wrap = s.bend_wrap_share * math.sqrt(a1 * a1 + a2 * a2)
        tips = [0.0, 0.0]
        torques = [0.0, 0.0]
        for i, plane in enumerate(self.planes):
            other = self.planes[1 - i].tip_rad
            tips[i], torques[i] = self._step_plane(plane, q[i], dt_s, warm_K, visc, bend_wrap,
                                                   other * other)
        return PlantStep(np.array(tips), np.array(torques))

    def _step_plane(self, pl: _Plane, q: float, dt: float, warm_K: float, visc: float,
                    bend_wrap: float, other_bend2: float) -> tuple[float, float]:
        p = pl.p
        r, rho, k1, k2 = pl.r, pl.rho, pl.k_handle, pl.k_shaft
        shrink = pl.shrink_per_K * warm_K
        slack_pos = p.slack_pos_mm + pl.extra_slack[0] - shrink
        slack_neg = p.slack_neg_mm + pl.extra_slack[1] - shrink
        phase = mesh_phase(q, p.pinion_teeth)
        k_mesh = mesh_stiffness(phase, p.mesh_stiffness_Nmm_per_deg, p.mesh_ripple)
        target = q * pl.ratio
        half_play = 0.5 * p.gear_play_deg
        shaft_wrap = p.sheath_wrap_deg * DEG + self.sheath_curvature_deg * DEG
        mu_b, mu_f = p.sheath_friction, p.film_friction
        fs, ft = pl.film_shaft, pl.film_tip
        mw_pos = min((mu_b + (mu_f - mu_b) * fs[0]) * shaft_wrap, MAX_FRICTION_RATIO)
        mw_neg = min((mu_b + (mu_f - mu_b) * fs[1]) * shaft_wrap, MAX_FRICTION_RATIO)
        mt_pos = min((mu_b + (mu_f - mu_b) * ft[0]) * bend_wrap, MAX_FRICTION_RATIO)
        mt_neg = min((mu_b + (mu_f - mu_b) * ft[1]) * bend_wrap, MAX_FRICTION_RATIO)
        drag = p.sheath_drag_N
        shear = p.film_viscous_N_s_per_mm * visc / dt if dt > 0.0 else 0.0
        vis_pos = shear / max(fs[0], 0.05) + 1e-9
        vis_neg = shear / max(fs[1], 0.05) + 1e-9
        damp = rho * rho * shear * (1.0 / max(ft[0], 0.05) + 1.0 / max(ft[1], 0.05))
        bend = pl.bend_Nmm * max(0.1, 1.0 - p.section_softening_per_K * warm_K)
        stiff = p.bend_stiffening_per_rad2
        drum0, tip0 = pl.drum_deg, pl.tip_rad
        u0_pos, u0_neg = pl.contact_mm
        r_rad = r * DEG
        drum_deg, tip = drum0, tip0
        draw_pos = r_rad * drum_deg - slack_pos
        draw_neg = -r_rad * drum_deg - slack_neg
        held = 0.0
        drum_per_tip = 0.0

        def drum_force(x: float) -> tuple[float, float]:
            """Mesh torque minus tendon torque on the drum (N mm) and its slope per deg."""
            nonlocal drum_per_tip
            dfl = play_deflection(target - x, half_play)
            t_pos, _, _, s_pos, c_pos, _, _ = _tendon(r_rad * x - slack_pos, rho * tip, u0_pos,
                                                      k1, k2, mw_pos, drag, vis_pos)
            t_neg, _, _, s_neg, c_neg, _, _ = _tendon(-r_rad * x - slack_neg, -rho * tip,
                                                      u0_neg, k1, k2, mw_neg, drag, vis_neg)
            slope = (-k_mesh if dfl != 0.0 else 0.0) - r * r_rad * (s_pos + s_neg)
            drum_per_tip = r * rho * (c_pos + c_neg) / slope if slope < 0.0 else 0.0
            return k_mesh * dfl - r * (t_pos - t_neg) - held, slope

        def tip_force(th: float, sign: float) -> tuple[float, float]:
            """Net moment on the section (N mm) less friction in direction ``sign``, less the
            film's shear, and its slope per rad; the shaft's contacts follow, and the drum
            by its linear response about the last drum solve (exact at convergence)."""
            dd = r_rad * drum_per_tip * (th - tip)
            _, _, t_pos, _, _, d_pos, e_pos = _tendon(draw_pos + dd, rho * th, u0_pos, k1, k2,
                                                      mw_pos, drag, vis_pos)
            _, _, t_neg, _, _, d_neg, e_neg = _tendon(draw_neg - dd, -rho * th, u0_neg, k1, k2,
                                                      mw_neg, drag, vis_neg)
            b2 = th * th + other_bend2
            f_pos, f_neg = 1.0 - sign * mt_pos, 1.0 + sign * mt_neg
            f = (rho * (t_pos * f_pos - t_neg * f_neg)
                 - sign * rho * 2.0 * drag - bend * th * (1.0 + stiff * b2) - damp * (th - tip0))
            slope = (rho * rho * (d_pos * f_pos + d_neg * f_neg)
                     + rho * r_rad * drum_per_tip * (e_pos * f_pos + e_neg * f_neg)
                     - bend * (1.0 + stiff * b2 + 2.0 * stiff * th * th) - damp)
            return f, slope

        def tip_moving(th: float) -> tuple[float, float]:
            return tip_force(th, tip_sign)

        tip_sign = 1.0
        for sweep in range(_SWEEPS):
            drum_before, tip_before = drum_deg, tip
            held = 0.0
            f0, d0 = drum_force(drum0)
            if abs(f0) > p.drum_friction_Nmm:
                held = p.drum_friction_Nmm if f0 > 0.0 else -p.drum_friction_Nmm
                x, fx, dx = drum0, f0 - held, d0
                if sweep:
                    x = drum_deg
                    fx, dx = drum_force(x)
                drum_deg = x if fx == 0.0 else root_decreasing(drum_force, x, fx, dx, 1e-6, 0.05,
                                                                        1e-4)
                drum_force(drum_deg)  # the drum's response to the tip, here
            else:
                drum_deg = drum0
                drum_per_tip = 0.0
            draw_pos = r_rad * drum_deg - slack_pos
            draw_neg = -r_rad * drum_deg - slack_neg
            up, d_up = tip_force(tip0, 1.0)
            down, d_down = tip_force(tip0, -1.0) if up <= 0.0 else (0.0, 0.0)
            if up > 0.0 or down < 0.0:
                tip_sign = 1.0 if up > 0.0 else -1.0
                x, fx, dx = tip0, (up if up > 0.0 else down), (d_up if up > 0.0 else d_down)
                if sweep:
                    x = tip
                    fx, dx = tip_moving(x)
                tip = x if fx == 0.0 else root_decreasing(tip_moving, x, fx, dx, 1e-8, 1e-3, 1e-5)
            else:
                tip = tip0
            if abs(drum_deg - drum_before) < 1e-5 and abs(tip - tip_before) < 1e-7:
                break
        draw_pos = r_rad * drum_deg - slack_pos
        draw_neg = -r_rad * drum_deg - slack_neg
        t_pos, u_pos, m_pos, *_ = _tendon(draw_pos, rho * tip, u0_pos, k1, k2, mw_pos, drag,
                                          vis_pos)
        t_neg, u_neg, m_neg, *_ = _tendon(draw_neg, -rho * tip, u0_neg, k1, k2, mw_neg, drag,
                                          vis_neg)
        pl.tension_N = [t_pos, t_neg]
        mid = (m_pos, m_neg)
        mesh_Nmm = k_mesh * play_deflection(target - drum_deg, half_play)
        if dt > 0.0:
            sq = p.squeeze_time_s * visc
            tip_speed = rho * abs(tip - tip0) / dt
            for j, travel in enumerate((abs(u_pos - u0_pos), abs(u_neg - u0_neg))):
                fs[j] = film_after(fs[j], shaft_wrap * mid[j] + drag, travel / dt, dt, sq,
                                   p.entrain_length_mm, p.rewet_time_s)
                ft[j] = film_after(ft[j], bend_wrap * mid[j] + drag, tip_speed, dt, sq,
                                   p.entrain_length_mm, p.rewet_time_s)
            knob_speed = (q - pl.knob_deg) / dt
        else:
            knob_speed = 0.0
        direction = math.tanh(knob_speed / 0.5)
        loss = mesh_loss(phase, p.mesh_friction, p.pinion_teeth, p.drum_teeth)
        knob_Nmm = pl.ratio * (mesh_Nmm + abs(mesh_Nmm) * loss * direction)
        torque_Nm = knob_Nmm / 1000.0 + p.handle_friction_Nm * math.tanh(knob_speed / 1.0)
        pl.drum_deg, pl.tip_rad, pl.knob_deg, pl.mesh_Nmm = drum_deg, tip, q, mesh_Nmm
        pl.contact_mm = [u_pos, u_neg]
        return tip / DEG, torque_Nm


def _shifted(value_slope: tuple[float, float], by: float) -> tuple[float, float]:
    return value_slope[0] - by, value_slope[1]


def make_warmgear_plant(knobs: Sequence[Mapping[str, Any]] | None = None,
                        sheath_curvature_deg: float = 0.0, **shaft: float) -> WarmGearPlant:
    """The warmgear plant: ``knobs`` overrides per knob (two mappings), the shaft's constants
    (:class:`ShaftParams` fields) as keywords, ``sheath_curvature_deg`` a bent shaft."""
    names = set(ShaftParams.__dataclass_fields__)
    unknown = sorted(set(shaft) - names)
    if unknown:
        raise PlantLoadError(f"unknown warmgear shaft constants: {', '.join(unknown)}")
    shaft_params = ShaftParams(**{k: float(v) for k, v in shaft.items()})
    if not (shaft_params.warm_time_s > 0.0 and 0.0 <= shaft_params.bend_wrap_share <= 2.0):
        raise PlantLoadError("warmgear warm_time_s must be > 0 and bend_wrap_share in [0, 2]")
    return WarmGearPlant(knob_params(knobs), shaft_params, sheath_curvature_deg)
