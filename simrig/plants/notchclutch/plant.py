"""The notchclutch plant: a slip clutch in the handle, aramid tendons on a hydrophilic liner, a
laser-cut steel section whose notches close, and a tip that rubs on the oesophageal wall.

Per step and per plane (anterior-posterior first, then right-left with the first plane's new
bend): the section's bend is found where the tendons' moment balances the notched tube's
elastic moment, unless the tip's friction on the wall holds it; each tendon's lumen contact
sticks or slides in closed form for a trial bend (:func:`laws.tendon_contact`), so the bend is a
scalar monotone root, found by bracketed false position. If the drum's torque then exceeds the
clutch's capacity the clutch slips: the drum angle is searched so that the torque sits at the
slipping capacity. Rate-dependent terms (the braid's stiffening with strain rate, the liner's
Stribeck rise with film speed) use the previous step's rates: they change slowly next to the
250 Hz step. The bending planes couple through the notch closure and the wrap (both set by the
total bend) and through the wall's friction (it grows with the total bend); ``coupling`` adds a
take-up of both tendons by the other plane's bend alone (0: as written).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.notchclutch.laws import (
    liner_drag_N,
    liner_friction,
    notch_moment_Nmm,
    tendon_contact,
)
from simrig.plants.notchclutch.params import NotchClutchKnob, knobs_from

_ROOT_TOL_NMM = 1e-7
_MAX_ITER = 60


class _Plane:
    """State and constants of one knob's drive and plane."""

    def __init__(self, knob: NotchClutchKnob) -> None:
        self.k = knob
        self.k1 = knob.tendon_stiffness_N / (knob.sheath_length_m * 1000.0)
        self.k2 = knob.tendon_stiffness_N / (knob.free_length_m * 1000.0)
        self.close_rad = math.radians(knob.notch_close_deg)
        self.width_rad = math.radians(knob.notch_close_width_deg)
        self.reset()

    def reset(self) -> None:
        self.bend_rad = 0.0
        self.contact_mm = [0.0, 0.0]
        self.stretch_mm = [0.0, 0.0]
        self.strain_rate = [0.0, 0.0]
        self.film_mm_s = [0.0, 0.0]
        self.slip_deg = 0.0
        self.slipping = False
        self.knob_deg = 0.0
        self.torque_Nm = 0.0
        self.slope_Nmm_per_rad = self.k.bend_stiffness_Nmm_per_rad + 2.0 * (
            self.k.tendon_offset_mm ** 2) * self.k1


class NotchClutchPlant:
    """Two knobs, each through a slip clutch to a drum pulling a pair of aramid tendons."""

    def __init__(self, knobs: tuple[NotchClutchKnob, NotchClutchKnob],
                 sheath_curvature_deg: float = 0.0, coupling: float = 0.0) -> None:
        self.knobs = knobs
        self.planes = (_Plane(knobs[0]), _Plane(knobs[1]))
        self.sheath_curvature_deg = float(sheath_curvature_deg)
        self.coupling = float(coupling)
        """Take-up of both tendons by the other plane's bend, ``coupling x offset x
        other^2 / 2`` mm (lumens set off their plane; 0: as written)."""
        self.slack_delta_mm = ((0.0, 0.0), (0.0, 0.0))
        self.t_s = 0.0

    def reset(self) -> None:
        """Straight, unloaded, freshly inserted (the coating starts to soak again)."""
        for p in self.planes:
            p.reset()
        self.t_s = 0.0

    def reshape(self, **changes: Any) -> None:
        """``slack_delta_mm`` ((pos, neg) per knob, added to the slack) or
        ``sheath_curvature_deg`` (extra wrap of the shaft): the catheter's shape changes."""
        for name, value in changes.items():
            if name == "slack_delta_mm":
                self.slack_delta_mm = tuple(  # type: ignore[assignment]
                    (float(a), float(b)) for a, b in value)
            elif name == "sheath_curvature_deg":
                self.sheath_curvature_deg = float(value)
            else:
                raise PlantLoadError(f"notchclutch cannot reshape {name!r}")

    @property
    def clutch_slip_deg(self) -> NDArray[np.float64]:
        """How far each drum has slipped behind its knob (diagnostic, not a sensor)."""
        return np.array([p.slip_deg for p in self.planes])

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q = step_inputs(dt_s, knob_deg)
        self.t_s += dt_s
        for i, plane in enumerate(self.planes):
            self._step_plane(i, plane, q[i], dt_s, self.planes[1 - i].bend_rad)
        return PlantStep(np.array([math.degrees(p.bend_rad) for p in self.planes]),
                         np.array([p.torque_Nm for p in self.planes]))

    # -- one plane ---------------------------------------------------------------------------

    def _step_plane(self, i: int, p: _Plane, q_deg: float, dt_s: float,
                    other_rad: float) -> None:
        k = p.k
        total_old = math.hypot(p.bend_rad, other_rad)
        wrap = math.radians(k.sheath_wrap_deg + self.sheath_curvature_deg) + (
            k.bend_wrap_share * total_old)
        ratios = [math.exp(wrap * liner_friction(
            k.sheath_friction, k.dry_friction_ratio, k.soak_time_s, self.t_s, k.stribeck_rise,
            p.film_mm_s[j], k.stribeck_speed_mm_s)) for j in (0, 1)]
        k1s = [p.k1 * (1.0 + k.rate_stiffening * math.log1p(
            p.strain_rate[j] / k.reference_strain_rate_per_s)) for j in (0, 1)]
        takeup_mm = self.coupling * k.tendon_offset_mm * other_rad * other_rad / 2.0
        slacks = (k.slack_pos_mm + self.slack_delta_mm[i][0] - takeup_mm,
                  k.slack_neg_mm + self.slack_delta_mm[i][1] - takeup_mm)
        hold_Nmm = k.tissue_friction_Nmm + k.tissue_friction_ratio * (
            k.bend_stiffness_Nmm_per_rad * total_old)
        drag = liner_drag_N(k.sheath_drag_N, k.dry_drag_ratio, k.soak_time_s, self.t_s)
        ctx = (p, k, ratios, k1s, slacks, hold_Nmm, other_rad, drag)

        drum_deg = q_deg - p.slip_deg
        bend, sol = self._solve_bend(ctx, drum_deg)
        torque = k.drum_radius_mm * (sol[1] - sol[4])
        limit = k.clutch_capacity_Nmm * (k.clutch_kinetic_ratio if p.slipping else 1.0)
        if abs(torque) > limit:
            drum_deg, bend, sol = self._slip(ctx, drum_deg, torque)
            torque = k.drum_radius_mm * (sol[1] - sol[4])
            p.slipping = True
        else:
            p.slipping = False
        p.slip_deg = q_deg - drum_deg
        pull = k.drum_radius_mm * math.radians(drum_deg)
        for j, (contact, x) in enumerate(((sol[0], pull), (sol[3], -pull))):
            stretch = x - slacks[j] - contact
            if dt_s > 0.0:
                p.strain_rate[j] = abs(stretch - p.stretch_mm[j]) / dt_s / (
                    k.sheath_length_m * 1000.0)
                speed = abs(contact - p.contact_mm[j]) / dt_s
                p.film_mm_s[j] += (speed - p.film_mm_s[j]) * min(1.0, dt_s / k.film_time_s)
            p.stretch_mm[j] = stretch
            p.contact_mm[j] = contact
        knob_speed = (q_deg - p.knob_deg) / dt_s if dt_s > 0.0 else 0.0
        p.knob_deg = q_deg
        p.bend_rad = bend
        p.torque_Nm = torque / 1000.0 + k.handle_friction_Nm * math.tanh(knob_speed / 2.0)

    @staticmethod
    def _residual(ctx: tuple[Any, ...], drum_deg: float, bend: float
                  ) -> tuple[float, tuple[float, ...]]:
        """Tendons' moment minus the tube's elastic moment at a trial bend, and the tendons."""
        p, k, ratios, k1s, slacks, _, other, drag = ctx
        pull = k.drum_radius_mm * math.radians(drum_deg)
        arm = k.tendon_offset_mm
        cp, t1p, t2p = tendon_contact(pull, slacks[0], p.contact_mm[0], arm * bend, k1s[0], p.k2,
                                      k.toe_mm, ratios[0], drag)
        cn, t1n, t2n = tendon_contact(-pull, slacks[1], p.contact_mm[1], -arm * bend, k1s[1],
                                      p.k2, k.toe_mm, ratios[1], drag)
        elastic = notch_moment_Nmm(k.bend_stiffness_Nmm_per_rad, bend, math.hypot(bend, other),
                                   p.close_rad, p.width_rad, k.notch_stiffening)
        return arm * (t2p - t2n) - elastic, (cp, t1p, t2p, cn, t1n, t2n)

    def _solve_bend(self, ctx: tuple[Any, ...], drum_deg: float
                    ) -> tuple[float, tuple[float, ...]]:
        """The bend at this drum angle: held by the wall's friction, or where the net moment
        equals the friction moment (false position on a bracket grown from the last bend)."""
        p, hold = ctx[0], ctx[5]
        b0 = p.bend_rad
        r0, sol0 = self._residual(ctx, drum_deg, b0)
        if abs(r0) <= hold:
            return b0, sol0
        target = math.copysign(hold, r0)
        fa, a = r0 - target, b0
        step = fa / p.slope_Nmm_per_rad
        while True:  # grow the bracket (the residual falls as the bend grows)
            b = a + step
            fb, solb = self._residual(ctx, drum_deg, b)
            fb -= target
            if (fb > 0.0) != (fa > 0.0) or abs(fb) <= _ROOT_TOL_NMM:
                break
            a, fa, step = b, fb, 2.0 * step
        if abs(fb) <= _ROOT_TOL_NMM:
            return b, solb
        x0, f0, x1, f1, side = a, fa, b, fb, 0
        for _ in range(_MAX_ITER):
            x = x1 - f1 * (x1 - x0) / (f1 - f0)
            fx, solx = self._residual(ctx, drum_deg, x)
            fx -= target
            if abs(fx) <= _ROOT_TOL_NMM or abs(x1 - x0) < 1e-12:
                break
            if (fx > 0.0) == (f1 > 0.0):
                x1, f1 = x, fx
                if side == 1:
                    f0 *= 0.5
                side = 1
            else:
                x0, f0 = x, fx
                if side == -1:
                    f1 *= 0.5
                side = -1
        if x != b0:
            p.slope_Nmm_per_rad = min(max(abs((r0 - target - fx) / (x - b0)),
                                          0.2 * ctx[1].bend_stiffness_Nmm_per_rad), 1e5)
        return x, solx

    def _slip(self, ctx: tuple[Any, ...], drum_deg: float, torque: float
              ) -> tuple[float, float, tuple[float, ...]]:
        """The drum angle at which the drum's torque is the clutch's slipping capacity."""
        k = ctx[1]
        target = math.copysign(k.clutch_capacity_Nmm * k.clutch_kinetic_ratio, torque)

        def excess(d: float) -> tuple[float, float, tuple[float, ...]]:
            bend, sol = self._solve_bend(ctx, d)
            return k.drum_radius_mm * (sol[1] - sol[4]) - target, bend, sol

        a, fa = drum_deg, torque - target
        step = -math.copysign(0.5, torque)
        while True:
            b = a + step
            fb, bend, sol = excess(b)
            if (fb > 0.0) != (fa > 0.0):
                break
            a, fa, step = b, fb, 2.0 * step
        for _ in range(_MAX_ITER):
            x = b - fb * (b - a) / (fb - fa)
            fx, bend, sol = excess(x)
            if abs(fx) <= 1e-6 or abs(b - a) < 1e-10:
                return x, bend, sol
            if (fx > 0.0) == (fb > 0.0):
                b, fb = x, fx
                fa *= 0.5
            else:
                a, fa = x, fx
                fb *= 0.5
        return x, bend, sol


def make_notchclutch_plant(knobs: Sequence[Mapping[str, Any] | NotchClutchKnob] | None = None,
                           sheath_curvature_deg: float = 0.0,
                           coupling: float = 0.0) -> NotchClutchPlant:
    """The notchclutch plant (``simrig.plants.notchclutch:make_notchclutch_plant``);
    ``coupling`` takes up both tendons by the other plane's bend (0: as written)."""
    if not math.isfinite(float(sheath_curvature_deg)):
        raise PlantLoadError("notchclutch: sheath_curvature_deg must be finite")
    if not (math.isfinite(float(coupling)) and float(coupling) >= 0.0):
        raise PlantLoadError(f"notchclutch: coupling must be >= 0, got {coupling!r}")
    return NotchClutchPlant(knobs_from(knobs), sheath_curvature_deg, float(coupling))
