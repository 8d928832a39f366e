"""The archwave plant: a strain-wave gearhead, tensioned tendons, a shaft through the anatomy.

Per knob, each step (quasi-static but for the friction and heat states):

1. The gearhead's output (the catheter's knob drum) lags the motor's output angle by the
   flexspline's twist (stiffening, Bouc-Wen hysteresis) and leads it by the kinematic error;
   the twist carries the load the last step asked (one step of lag, stable as long as the
   gear is stiffer than the tendons at the drum, which it is by ten times).
2. Each tendon's draw-in, less what the patient's path frees and what the bending section
   takes, loads a spring-loaded tensioner (soft floor) and then the stiff tendon and coil.
3. The coil sheath's friction bounds the distal tension in a band around the proximal one
   (``T_p / g - drag`` to ``T_p * g + drag``, ``g = exp(mu * wrap)``); inside the band the
   distal tension sticks. The wrap is the path's two bends plus the section's total bend, so
   each knob's tendons feel the other knob's bend.
4. The section bends until its stiffening cover balances the distal tensions (Newton with a
   bracket on the one tip angle).
5. The knob torque is the drum's tendon torque and seal friction (its direction from the
   knob's motion: the twist's own chatter would flip it), plus the gearhead's wave
   generator drag, plus the motor's cogging, divided by how far the motor's torque constant
   is from its data sheet (unit lot and a winding that warms in the sealed handle).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.archwave.laws import (
    cogging_knob_Nm,
    flex_twist,
    kinematic_error_rad,
    motor_current_A,
    path_slack_mm,
    tensioner_tension,
    winding_rise_K,
)
from simrig.plants.archwave.params import ArchWaveKnob, ShaftPath, knobs_from, path_from

LUMEN_DEG = ((0.0, 180.0), (90.0, 270.0))
"""Azimuth of each knob's (pos, neg) tendon lumen in the shaft."""
_SPEED_SCALE_RAD_S = math.radians(2.0)
"""Speed over which Coulomb drags build up (tanh smoothing)."""


def _tendon(e_mm: float, slack_mm: float, k: ArchWaveKnob, c_free: float, c_sheath: float,
            g: float, td_prev: float) -> tuple[float, float, float]:
    """Proximal and distal tension (N) of one tendon drawn in by ``e_mm`` past its rest, and
    the distal tension's slope d(T_d)/de (N/mm).

    Past the idler's stop the tendon stretches with its mean tension: the free length with the
    proximal tension, the sheathed length with the mean of the two ends. The coil's friction
    holds the distal tension inside ``[T_p / g - drag, T_p * g + drag]``: inside, it sticks
    (the tip holds while the proximal tension changes: backlash); on an edge it slides.
    """
    drag = k.sheath_drag_N
    floor = k.tensioner_preload_N + k.tensioner_rate_N_per_mm * slack_mm
    if e_mm <= slack_mm:
        tp, dtp = tensioner_tension(e_mm, slack_mm, k.tensioner_preload_N,
                                    k.tensioner_rate_N_per_mm, k.tensioner_reserve_mm,
                                    1.0 / (c_free + c_sheath))
        lo, hi = max(0.0, tp / g - drag), tp * g + drag
        if td_prev < lo:
            return tp, lo, (dtp / g if lo > 0.0 else 0.0)
        if td_prev > hi:
            return tp, hi, dtp * g
        return tp, td_prev, 0.0
    stretch = e_mm - slack_mm
    c = c_free + 0.5 * c_sheath
    tp = floor + (stretch - 0.5 * c_sheath * (td_prev - floor)) / c
    lo, hi = max(0.0, tp / g - drag), tp * g + drag
    if lo <= td_prev <= hi:
        return tp, td_prev, 0.0
    if td_prev < lo:  # drawn in: the tendon slides towards the handle
        slope = 1.0 / (c + 0.5 * c_sheath / g)
        tp = floor + slope * (stretch + 0.5 * c_sheath * (drag + floor * (1.0 - 1.0 / g)))
        return tp, max(0.0, tp / g - drag), slope / g
    slope = 1.0 / (c + 0.5 * c_sheath * g)  # released: it slides back towards the tip
    tp = floor + slope * (stretch - 0.5 * c_sheath * (drag - floor * (1.0 - g)))
    return max(tp, floor), g * max(tp, floor) + drag, slope * g


def _tip_residual(theta: float, k: ArchWaveKnob, other: float, drum_mm: float,
                  free_pos: float, free_neg: float, g: float, c_free: float, c_sheath: float,
                  td_pos: float, td_neg: float) -> tuple[float, float, float, float, float, float]:
    """Moment balance of the section at tip angle ``theta`` (rad): residual (N m), its slope,
    and the tendons' proximal and distal tensions (N) it implies."""
    rho = k.tendon_offset_mm
    tp_pos, td_pos, s_pos = _tendon(drum_mm - rho * theta - free_pos, k.slack_pos_mm, k,
                                    c_free, c_sheath, g, td_pos)
    tp_neg, td_neg, s_neg = _tendon(-drum_mm + rho * theta - free_neg, k.slack_neg_mm, k,
                                    c_free, c_sheath, g, td_neg)
    kb, c = k.bend_stiffness_Nm_per_rad, k.bend_stiffening_per_rad2
    arm_m = rho * 1e-3
    r = kb * theta * (1.0 + c * (theta * theta + other * other)) - arm_m * (td_pos - td_neg)
    dr = kb * (1.0 + c * (3.0 * theta * theta + other * other)) + arm_m * rho * (s_pos + s_neg)
    return r, dr, tp_pos, tp_neg, td_pos, td_neg


class ArchWavePlant:
    """Two knobs through strain-wave gearheads; tendons with spring tensioners; a shaft laid
    through two bends in different planes (see the module docstring)."""

    def __init__(self, knobs: tuple[ArchWaveKnob, ArchWaveKnob], path: ShaftPath,
                 sheath_curvature_deg: float = 0.0) -> None:
        self.knobs = knobs
        self.path = path
        self.sheath_curvature_deg = sheath_curvature_deg
        self._slack_delta_mm = [[0.0, 0.0], [0.0, 0.0]]
        self._c_free = [k.free_length_m * 1e3 / k.tendon_stiffness_N for k in knobs]
        """Compliance of the free tendon in the handle (mm/N)."""
        self._c_sheath = [k.sheath_length_m * 1e3 / k.tendon_stiffness_N
                          + k.coil_compliance_mm_per_N for k in knobs]
        """Compliance of the sheathed tendon and its coil (mm/N)."""
        self._geometry()
        self.reset()

    def _geometry(self) -> None:
        """What the path frees per tendon and the path's wrap (rad), after a reshape too."""
        p = self.path
        bends = ((p.arch_deg + self.sheath_curvature_deg, p.arch_plane_deg),
                 (p.turn_deg, p.turn_plane_deg))
        self._free_mm = [[path_slack_mm(LUMEN_DEG[i][j], bends, k.coil_clearance_mm,
                                        k.lumen_offset_mm) + self._slack_delta_mm[i][j]
                          for j in (0, 1)] for i, k in enumerate(self.knobs)]
        path_wrap = math.radians(p.arch_deg + self.sheath_curvature_deg + p.turn_deg)
        self._wrap_rad = [path_wrap + math.radians(k.sheath_wrap_deg) for k in self.knobs]

    def reset(self) -> None:
        self.tip_rad = [0.0, 0.0]
        self._twist = [0.0, 0.0]
        self._z = [0.0, 0.0]
        self._out_rad: list[float | None] = [None, None]
        self._load_Nm = [0.0, 0.0]
        self.winding_rise_K = [0.0, 0.0]
        self.proximal_N = [[0.0, 0.0], [0.0, 0.0]]
        self.distal_N: list[list[float]] = []
        for i, k in enumerate(self.knobs):
            rest = [tensioner_tension(-self._free_mm[i][j], s, k.tensioner_preload_N,
                                      k.tensioner_rate_N_per_mm, k.tensioner_reserve_mm,
                                      1.0 / (self._c_free[i] + self._c_sheath[i]))[0]
                    for j, s in enumerate((k.slack_pos_mm, k.slack_neg_mm))]
            self.distal_N.append(rest)

    def reshape(self, **changes: Any) -> None:
        """``slack_delta_mm`` ((pos, neg) per knob, added to the slack the tensioners take
        up) or ``sheath_curvature_deg`` (added to the arch)."""
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
                if not (math.isfinite(float(value)) and float(value) >= 0.0):
                    raise PlantLoadError("sheath_curvature_deg must be >= 0")
                self.sheath_curvature_deg = float(value)
            else:
                raise PlantLoadError(f"archwave cannot reshape {name}")
        self._geometry()

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q = step_inputs(dt_s, knob_deg)
        section = math.hypot(self.tip_rad[0], self.tip_rad[1])
        torques = [0.0, 0.0]
        for i, k in enumerate(self.knobs):
            torques[i] = self._knob_step(i, k, dt_s, math.radians(q[i]), section)
        return PlantStep(np.degrees(np.array(self.tip_rad)), np.array(torques))

    def _knob_step(self, i: int, k: ArchWaveKnob, dt_s: float, out_rad: float,
                   section_rad: float) -> float:
        drum = (out_rad + kinematic_error_rad(out_rad, k.kinematic_error_deg,
                                              k.kinematic_phase_deg) - self._twist[i])
        prev_out = self._out_rad[i]
        out_speed = 0.0 if prev_out is None or dt_s <= 0.0 else (out_rad - prev_out) / dt_s
        self._out_rad[i] = out_rad
        g = math.exp(k.sheath_friction * (self._wrap_rad[i] + k.section_wrap_share * section_rad))
        tp_pos, tp_neg = self._solve_tip(i, k, drum * k.pulley_radius_mm, g)
        load = (k.pulley_radius_mm * 1e-3 * (tp_pos - tp_neg)
                + k.handle_friction_Nm * math.tanh(out_speed / _SPEED_SCALE_RAD_S))
        self._twist[i], self._z[i] = flex_twist(
            load, self._twist[i], self._z[i], k.flex_stiffness_Nm_per_rad,
            k.flex_stiffening_Nm_per_rad3, k.flex_elastic_share,
            math.radians(k.flex_hysteresis_deg))
        out = (load + k.wave_drag_Nm * math.tanh(out_speed / _SPEED_SCALE_RAD_S)
               + k.wave_viscous_Nm_s_per_rad * out_speed
               + cogging_knob_Nm(out_rad, k.gear_ratio, k.cogging_mNm, k.cogging_per_rev))
        current = motor_current_A(out, k.gear_ratio)
        power = k.standby_power_W + current * current * k.winding_resistance_ohm
        self.winding_rise_K[i] = winding_rise_K(self.winding_rise_K[i], dt_s, power,
                                                k.thermal_resistance_K_per_W, k.thermal_time_s)
        kt = k.torque_constant_ratio * (1.0 - k.kt_temp_coeff_per_K * self.winding_rise_K[i])
        return out / kt

    def _solve_tip(self, i: int, k: ArchWaveKnob, drum_mm: float, g: float
                   ) -> tuple[float, float]:
        """Section angle where the moments balance (Newton inside a shrinking bracket)."""
        other = self.tip_rad[1 - i]
        free_pos, free_neg = self._free_mm[i]
        td_pos, td_neg = self.distal_N[i]
        c_free, c_sheath = self._c_free[i], self._c_sheath[i]
        lo, hi = -math.pi, math.pi
        theta = self.tip_rad[i]
        for _ in range(60):
            r, dr, tp_pos, tp_neg, d_pos, d_neg = _tip_residual(
                theta, k, other, drum_mm, free_pos, free_neg, g, c_free, c_sheath, td_pos, td_neg)
            if abs(r) < 1e-12:
                break
            if r > 0.0:
                hi = theta
            else:
                lo = theta
            nxt = theta - r / dr
            if not lo < nxt < hi:
                nxt = 0.5 * (lo + hi)
            if abs(nxt - theta) < 1e-12:
                break
            theta = nxt
        self.tip_rad[i] = theta
        self.proximal_N[i] = [tp_pos, tp_neg]
        self.distal_N[i] = [d_pos, d_neg]
        return tp_pos, tp_neg


def make_archwave_plant(knobs: Sequence[Mapping[str, Any]] | None = None,
                        sheath_curvature_deg: float = 0.0, **path: Any) -> ArchWavePlant:
    """The archwave plant (nominal unit by default); ``knobs`` overrides constants per knob,
    the path's keywords (``arch_deg`` ...) the patient's anatomy."""
    try:
        curvature = float(sheath_curvature_deg)
    except (TypeError, ValueError):
        raise PlantLoadError("sheath_curvature_deg must be a number") from None
    if not (math.isfinite(curvature) and curvature >= 0.0):
        raise PlantLoadError(f"sheath_curvature_deg must be >= 0, got {sheath_curvature_deg!r}")
    return ArchWavePlant(knobs_from(knobs), path_from(path), curvature)
