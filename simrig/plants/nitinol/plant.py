"""The nitinol plant: a superelastic NiTi spine, an asymmetric section, a lubricated sheath.

Per knob: a drum of radius r draws one tendon and pays out the other; each tendon is a slack,
elastic rope with one lumped lumen contact (:func:`laws.slide_contact`) between its handle part
and its tip part; the tip part ends on the bending section at its lumen's offset (different on
the two sides). The section's bend in this plane balances the tendons' moments against the cover
(linear) and the NiTi tube, whose flag-shaped loop (:func:`laws.tube_moment`) is shared by both
planes. Each step solves, per knob, the bend at which the moments balance (the contacts answer
in closed form for a given bend), with the other plane's bend from its latest solve.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.nitinol.laws import slide_contact, transform, tube_moment
from simrig.plants.nitinol.params import Backbone, NitinolKnobParams, backbone, knob_params

BEND_LIMIT_RAD = math.radians(170.0)
"""The links close long before this; it only bounds the bend search."""


class _Knob:
    """One knob's constants in solver units (mm, N, rad) and its state."""

    def __init__(self, p: NitinolKnobParams, curvature_deg: float) -> None:
        self.p = p
        self.r_mm = p.pulley_radius_mm
        self.a_mm = (p.tendon_offset_mm, p.tendon_offset_mm * p.offset_ratio_neg)
        self.slack_mm = [p.slack_pos_mm, p.slack_neg_mm]
        proximal_mm = (p.free_length_m + p.contact_fraction * p.sheath_length_m) * 1e3
        distal_mm = (1.0 - p.contact_fraction) * p.sheath_length_m * 1e3 + p.bend_length_mm
        self.kp = p.tendon_stiffness_N / proximal_mm
        self.kd = p.tendon_stiffness_N / distal_mm
        self.kc = p.cover_stiffness_Nm_per_rad
        self.handle_k_Nm_rad = p.handle_friction_Nm / max(
            math.radians(p.handle_presliding_deg), 1e-9)
        self.set_wrap(curvature_deg)
        self.reset()

    def set_wrap(self, curvature_deg: float) -> None:
        self.wrap_rad = math.radians(self.p.sheath_wrap_deg + curvature_deg)

    def reset(self) -> None:
        self.u_mm = [0.0, 0.0]
        self.tension_N = [0.0, 0.0, 0.0, 0.0]  # handle +, tip +, handle -, tip -
        self.bend_rad = 0.0
        self.knob_rad = 0.0
        self.handle_Nm = 0.0


class NitinolPlant:
    """Two knobs bending one section with a superelastic spine (see the module docstring)."""

    def __init__(self, knobs: Sequence[NitinolKnobParams], temperature_C: float = 37.0,
                 sheath_curvature_deg: float = 0.0) -> None:
        self.knobs = [_Knob(p, sheath_curvature_deg) for p in knobs]
        self.temperature_C = temperature_C
        self.sheath_curvature_deg = sheath_curvature_deg
        self.backbone: Backbone = backbone(knobs, temperature_C)
        self.fraction = 0.0
        """Martensite fraction of the tube (0: all austenite)."""

    def reset(self) -> None:
        for k in self.knobs:
            k.reset()
        self.fraction = 0.0

    def reshape(self, **changes: Any) -> None:
        """Shape changes mid-run: ``slack_delta_mm=((pos, neg), (pos, neg))`` (mm added to
        each tendon's slack) and ``sheath_curvature_deg`` (extra wrap on every lumen)."""
        unknown = sorted(set(changes) - {"slack_delta_mm", "sheath_curvature_deg"})
        if unknown:
            raise PlantLoadError(f"the nitinol plant cannot reshape {', '.join(unknown)}")
        if "slack_delta_mm" in changes:
            for k, delta in zip(self.knobs, changes["slack_delta_mm"], strict=True):
                k.slack_mm = [max(0.0, s + float(d)) for s, d in zip(k.slack_mm, delta,
                                                                      strict=True)]
        if "sheath_curvature_deg" in changes:
            self.sheath_curvature_deg = float(changes["sheath_curvature_deg"])
            for k in self.knobs:
                k.set_wrap(self.sheath_curvature_deg)

    def step(self, dt_s: float, knob_deg: Any) -> PlantStep:
        q = step_inputs(dt_s, knob_deg)
        film_scale = 1.0 / max(dt_s, 1e-6)
        bends = [k.bend_rad for k in self.knobs]
        resultant = math.hypot(*bends)
        torque = [0.0, 0.0]
        for i, k in enumerate(self.knobs):
            q_rad = math.radians(q[i])
            wrap = k.wrap_rad + resultant  # the bent section adds its bend to every lumen
            mu_half = 0.5 * k.p.sheath_friction * wrap
            film = k.p.film_damping_N_s_per_mm * film_scale
            bends[i] = self._solve_bend(k, q_rad, bends[1 - i], mu_half, film)
            # handle O-ring: elastic until it slides (one Jenkins element)
            k.handle_Nm += k.handle_k_Nm_rad * (q_rad - k.knob_rad)
            cap = k.p.handle_friction_Nm
            k.handle_Nm = min(cap, max(-cap, k.handle_Nm))
            k.knob_rad = q_rad
            t = k.tension_N
            torque[i] = k.r_mm * 1e-3 * (t[0] - t[2]) + k.handle_Nm
        self.fraction = transform(self.backbone, math.hypot(*bends), self.fraction)
        return PlantStep(np.degrees(np.array(bends)), np.array(torque))

    def _balance(self, k: _Knob, q_rad: float, bend: float, other: float, mu_half: float,
                 film: float) -> tuple[float, list[float], list[float]]:
        """Moment left over at ``bend`` (tendons minus tube and cover, Nm), nodes, tensions."""
        draw = k.r_mm * q_rad
        up, tp, td = slide_contact(draw - k.slack_mm[0], k.a_mm[0] * bend, k.u_mm[0], k.kp,
                                   k.kd, mu_half, k.p.sheath_drag_N, film)
        un, tpn, tdn = slide_contact(-draw - k.slack_mm[1], -k.a_mm[1] * bend, k.u_mm[1], k.kp,
                                     k.kd, mu_half, k.p.sheath_drag_N, film)
        tube, _ = tube_moment(self.backbone, bend, other, self.fraction)
        rest = (k.a_mm[0] * td - k.a_mm[1] * tdn) * 1e-3 - tube - k.kc * bend
        return rest, [up, un], [tp, td, tpn, tdn]

    def _solve_bend(self, k: _Knob, q_rad: float, other: float, mu_half: float,
                    film: float) -> float:
        """The bend where the moments balance: the balance falls with the bend, so a bracket
        and regula falsi (Illinois) find it; the contacts' kinks make it piecewise smooth."""
        bb = self.backbone
        soft = k.kc + bb.stiffness_Nm_per_rad * bb.hardening_Nm / (
            bb.stiffness_Nm_per_rad * bb.transformation_rad + bb.hardening_Nm)
        x0 = k.bend_rad
        f0, u0, t0 = self._balance(k, q_rad, x0, other, mu_half, film)
        if abs(f0) < 1e-10:
            k.u_mm, k.tension_N = u0, t0
            return x0
        # the balance falls at least as fast as the softest moment rises: this step overshoots
        x1 = min(BEND_LIMIT_RAD, max(-BEND_LIMIT_RAD, x0 + f0 / soft))
        f1, u1, t1 = self._balance(k, q_rad, x1, other, mu_half, film)
        best = (abs(f1), x1, u1, t1)
        for _ in range(60):
            if best[0] < 1e-10 or abs(x1 - x0) < 1e-12 or f1 == f0:
                break
            x2 = x1 - f1 * (x1 - x0) / (f1 - f0)
            f2, u2, t2 = self._balance(k, q_rad, x2, other, mu_half, film)
            if abs(f2) < best[0]:
                best = (abs(f2), x2, u2, t2)
            if (f2 > 0.0) != (f1 > 0.0):
                x0, f0 = x1, f1
            else:  # the kept end's value halved (Illinois): no stalling on one side
                f0 *= 0.5
            x1, f1 = x2, f2
        _, k.bend_rad, k.u_mm, k.tension_N = best
        return k.bend_rad


def make_nitinol_plant(knobs: Sequence[Mapping[str, Any]] | None = None,
                       temperature_C: float = 37.0,
                       sheath_curvature_deg: float = 0.0) -> NitinolPlant:
    """The nitinol plant: ``knobs`` overrides per knob (``[{...}, {...}]``), the tube's
    temperature (body: 37 C; the plateaus shift by the Clausius-Clapeyron slope) and an extra
    sheath bend (deg)."""
    for name, v in (("temperature_C", temperature_C),
                    ("sheath_curvature_deg", sheath_curvature_deg)):
        if not (isinstance(v, (int, float)) and math.isfinite(v)):
            raise PlantLoadError(f"{name} must be a finite number, got {v!r}")
    if sheath_curvature_deg < 0.0:
        raise PlantLoadError(f"sheath_curvature_deg must be >= 0, got {sheath_curvature_deg!r}")
    return NitinolPlant(knob_params(knobs), float(temperature_C), float(sheath_curvature_deg))
