"""The wormeyelet plant: a worm-stage handle with a silicone damper on each knob, stainless ropes
over one lumped lumen contact, and a spacer-disk bending section whose eyelets the ropes rub.

Per plane and step: the wheel sits on the flank its rope load pushes it against (free in its
play while both ropes are slack), the ropes' contacts stick or slide in closed form for a trial
bend, and the section sticks while the net distal tension lies inside its eyelet band, otherwise
a safeguarded Newton finds the bend on the band's edge. The knob torque is the drum load through
the worm at the efficiency of the power flow's direction, plus the seal and the damper.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantStep, step_inputs
from simrig.plants.wormeyelet.laws import (
    RopeState,
    damper_torque,
    eyelet_band,
    rope,
    worm_knob_torque,
)
from simrig.plants.wormeyelet.params import WormEyeletKnob, knobs_from

_LOAD_EPS_N = 1e-3
"""Net rope tension below which the wheel counts as unloaded (free in its play)."""
_SEAL_SPEED_RAD_S = math.radians(0.2)
"""Speed over which the seal's Coulomb friction builds up (tanh: keeps it deterministic)."""


class _Plane:
    """One knob, its two ropes and its bending plane."""

    def __init__(self, k: WormEyeletKnob) -> None:
        self.k = k
        self.eta_drive = k.drive_efficiency
        self.eta_back = k.back_efficiency
        ea = k.tendon_stiffness_N
        shaft_mm = k.sheath_length_m * 1000.0
        self.c_prox = k.contact_fraction * shaft_mm / ea
        self.c_dist = ((1.0 - k.contact_fraction) * shaft_mm + k.section_length_mm) / ea
        self.play_rad = math.radians(k.worm_play_deg)
        self.section_N_per_rad = k.section_stiffness_Nmm_per_rad / k.tendon_offset_mm
        self.reset()

    def reset(self) -> None:
        self.knob_rad = 0.0
        self.speed_rad_s = 0.0
        self.wheel_rad = 0.0
        self.load_sign = 0.0
        self.driving = True
        self.bend_rad = 0.0
        self.contact_mm = [0.0, 0.0]
        self.proximal_N = [0.0, 0.0]

    def ropes(self, bend: float, draw: tuple[float, float], ratio: float
              ) -> tuple[RopeState, RopeState]:
        arm = self.k.tendon_offset_mm
        plus = rope(draw[0], arm * bend, 1.0, arm, self.contact_mm[0], self.c_prox, self.c_dist,
                    ratio, self.k.sheath_drag_N)
        minus = rope(draw[1], -arm * bend, -1.0, arm, self.contact_mm[1], self.c_prox,
                     self.c_dist, ratio, self.k.sheath_drag_N)
        return plus, minus

    def bend_on_edge(self, draw: tuple[float, float], ratio: float, cross: float,
                     loading: bool) -> float:
        """The bend where the net distal tension meets the band's upper (loading) or lower edge:
        the net falls with the bend and the edge rises, so the root is bracketed and unique."""
        k = self.k
        arm = k.tendon_offset_mm
        if loading:
            lo_b = self.bend_rad
            hi_b = max(self.bend_rad, 0.0, max(draw[0], self.contact_mm[0]) / arm) + 1e-6
        else:
            lo_b = min(self.bend_rad, 0.0, -max(draw[1], self.contact_mm[1]) / arm) - 1e-6
            hi_b = self.bend_rad
        x = self.bend_rad
        for _ in range(60):
            plus, minus = self.ropes(x, draw, ratio)
            lo, hi, dlo, dhi = eyelet_band(x, self.section_N_per_rad, k.eyelet_friction, cross,
                                           k.disk_friction_N)
            net = plus.distal_N - minus.distal_N
            f = net - (hi if loading else lo)
            df = plus.d_distal_N_per_rad - minus.d_distal_N_per_rad - (dhi if loading else dlo)
            if abs(f) < 1e-9:
                return x
            if f > 0.0:
                lo_b = x
            else:
                hi_b = x
            if hi_b - lo_b < 1e-12:
                return x
            step = x - f / df if df < 0.0 else math.nan
            x = step if lo_b < step < hi_b else 0.5 * (lo_b + hi_b)
        return x

    def step(self, knob_rad: float, dt_s: float, ratio: float, cross: float,
             slack: tuple[float, float]) -> tuple[float, float]:
        """Advance to ``knob_rad``; (bend rad, knob torque N m)."""
        k = self.k
        if dt_s > 0.0:
            self.speed_rad_s = (knob_rad - self.knob_rad) / dt_s
        self.knob_rad = knob_rad
        worm = knob_rad / k.worm_ratio
        half = 0.5 * self.play_rad
        wheel_before = self.wheel_rad
        if self.load_sign > 0.0:
            self.wheel_rad = worm - half
        elif self.load_sign < 0.0:
            self.wheel_rad = worm + half
        else:
            self.wheel_rad = min(max(self.wheel_rad, worm - half), worm + half)
        r = k.drum_radius_mm
        draw = (r * self.wheel_rad - slack[0], -r * self.wheel_rad - slack[1])
        plus, minus = self.ropes(self.bend_rad, draw, ratio)
        lo, hi, _, _ = eyelet_band(self.bend_rad, self.section_N_per_rad, k.eyelet_friction,
                                   cross, k.disk_friction_N)
        net = plus.distal_N - minus.distal_N
        if net > hi or net < lo:
            self.bend_rad = self.bend_on_edge(draw, ratio, cross, loading=net > hi)
            plus, minus = self.ropes(self.bend_rad, draw, ratio)
        self.contact_mm = [plus.contact_mm, minus.contact_mm]
        self.proximal_N = [plus.proximal_N, minus.proximal_N]
        pull = plus.proximal_N - minus.proximal_N
        self.load_sign = 0.0 if abs(pull) < _LOAD_EPS_N else math.copysign(1.0, pull)
        drum_Nm = r * pull / 1000.0
        moved = self.wheel_rad - wheel_before
        if moved * drum_Nm != 0.0:
            self.driving = moved * drum_Nm > 0.0
        torque = worm_knob_torque(drum_Nm, self.driving, k.worm_ratio, self.eta_drive,
                                  self.eta_back)
        torque += k.handle_friction_Nm * math.tanh(self.speed_rad_s / _SEAL_SPEED_RAD_S)
        torque += damper_torque(self.speed_rad_s, k.damper_Nm_s_per_rad,
                                k.damper_thinning_rad_s)
        return self.bend_rad, torque


class WormEyeletPlant:
    """Two knobs through worm stages, ropes over a lumen contact, a spacer-disk section."""

    def __init__(self, knobs: Sequence[WormEyeletKnob], sheath_curvature_deg: float = 0.0,
                 slack_delta_mm: Sequence[Sequence[float]] = ((0.0, 0.0), (0.0, 0.0))) -> None:
        self.knobs = tuple(knobs)
        self.planes = [_Plane(k) for k in self.knobs]
        self.sheath_curvature_deg = 0.0
        self.slack_delta_mm = ((0.0, 0.0), (0.0, 0.0))
        self.reshape(sheath_curvature_deg=sheath_curvature_deg, slack_delta_mm=slack_delta_mm)

    def reshape(self, **changes: Any) -> None:
        """Change the shaft's curvature (deg, added to every rope's wrap) or the slack (mm per
        knob, (+, -)) mid-run; the state stays."""
        unknown = sorted(set(changes) - {"sheath_curvature_deg", "slack_delta_mm"})
        if unknown:
            raise ValueError(f"wormeyelet cannot reshape {', '.join(unknown)}")
        if "sheath_curvature_deg" in changes:
            curvature = float(changes["sheath_curvature_deg"])
            if not (math.isfinite(curvature) and curvature >= 0.0):
                raise ValueError(f"sheath_curvature_deg must be >= 0, got {curvature!r}")
            self.sheath_curvature_deg = curvature
        if "slack_delta_mm" in changes:
            d = changes["slack_delta_mm"]
            self.slack_delta_mm = ((float(d[0][0]), float(d[0][1])),
                                   (float(d[1][0]), float(d[1][1])))
        self._ratio = [math.exp(k.sheath_friction * math.radians(
            k.sheath_wrap_deg + self.sheath_curvature_deg)) for k in self.knobs]

    def reset(self) -> None:
        for p in self.planes:
            p.reset()

    @property
    def proximal_tension_N(self) -> NDArray[np.float64]:
        """Rope tensions at the drums, [[+, -], [+, -]] (diagnostics)."""
        return np.array([p.proximal_N for p in self.planes])

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q = step_inputs(dt_s, knob_deg)
        bends = [p.bend_rad for p in self.planes]
        torque = [0.0, 0.0]
        for i, plane in enumerate(self.planes):
            k = plane.k
            slack = (k.slack_pos_mm + self.slack_delta_mm[i][0],
                     k.slack_neg_mm + self.slack_delta_mm[i][1])
            cross = k.cross_wrap * abs(bends[1 - i])
            bends[i], torque[i] = plane.step(math.radians(q[i]), dt_s, self._ratio[i], cross,
                                             slack)
        return PlantStep(np.degrees(np.array(bends)), np.array(torque))


def make_wormeyelet_plant(knobs: Sequence[Mapping[str, Any]] | None = None,
                          sheath_curvature_deg: float = 0.0,
                          slack_delta_mm: Sequence[Sequence[float]] = ((0.0, 0.0), (0.0, 0.0)),
                          ) -> WormEyeletPlant:
    """The ``module:factory`` entry: per-knob overrides of the nominal constants."""
    return WormEyeletPlant(knobs_from(knobs), sheath_curvature_deg, slack_delta_mm)
