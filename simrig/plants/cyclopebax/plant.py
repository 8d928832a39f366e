"""The cyclopebax plant: a cycloidal adapter, a knob brake, lay-dependent lumen friction, a
three-durometer Pebax section whose neutral axis moves, and ropes that set when overloaded.

Per knob (one plane) and step, quasi-static:

1. the reducer: the drum sits on the flank the tendons pull it against (lost motion shows only
   when the load changes side), offset by the pin contacts' Hertzian twist under the last
   step's load; with no load the drum bushing holds it inside the clearance;
2. the two ropes: slack and set taken off the drum's draw-in, the section's take-up (its own
   and the other plane's) off what the section needs; each rope's lumen contact holds or
   slides at a capstan grip that depends on the sliding direction (the rope's lay against the
   coil's winding);
3. the section: the bend where the ropes' generalised force (tension x (arm -/+ axis shift))
   meets the three zones' moment, by a bracketed Newton search from the last bend;
4. the knob torque: the drum's load through the reducer with its load-dependent mesh loss
   (more while driving, less while back-driven), plus the brake, both with presliding.

The planes meet through the section: the other plane's bend adds wrap to the lumen contacts and
takes up every rope by its neutral-axis travel (both lagged by one step).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.cyclopebax.laws import (
    SectionTable,
    grips,
    lumen_contact,
    mesh_twist_deg,
    section_at,
    section_table,
)
from simrig.plants.cyclopebax.params import (
    NOMINAL_KNOBS,
    SECTION_LUMEN_FRICTION_SHARE,
    CycloPebaxKnob,
    knob_from,
)

_DEG = math.pi / 180.0


class CycloPebaxPlant:
    """Two knobs of the cyclopebax catheter (see the module docstring)."""

    def __init__(self, knobs: Sequence[CycloPebaxKnob],
                 sheath_curvature_deg: float = 0.0, coupling: float = 0.0) -> None:
        if len(knobs) != 2:
            raise PlantLoadError(f"cyclopebax takes 2 knobs, got {len(knobs)}")
        if not (math.isfinite(sheath_curvature_deg) and sheath_curvature_deg >= 0.0):
            raise PlantLoadError(f"cyclopebax sheath_curvature_deg must be >= 0, got "
                                 f"{sheath_curvature_deg!r}")
        if not (math.isfinite(coupling) and coupling >= 0.0):
            raise PlantLoadError(f"cyclopebax coupling must be >= 0, got {coupling!r}")
        self.knobs = tuple(knobs)
        self.sheath_curvature_deg = float(sheath_curvature_deg)
        # the other plane's neutral-axis take-up on this plane's ropes, as a share of what the
        # section as written takes (``coupling`` adds to it: lumens set off their plane)
        self.cross_takeup_share = 1.0 + float(coupling)
        self.slack_delta_mm = [[0.0, 0.0], [0.0, 0.0]]
        self._tables: list[SectionTable] = [section_table(k.bend_stiffness_Nmm_per_rad)
                                            for k in self.knobs]
        self._k = [self._stiffness(k) for k in self.knobs]
        self.reset()

    @staticmethod
    def _stiffness(k: CycloPebaxKnob) -> tuple[float, float]:
        """Rope stiffness (N/mm) from the drum to the lumen contact and from it to the section
        (the contact sits at the middle of the sheath, the friction's centroid)."""
        half = 500.0 * k.sheath_length_m
        return (k.tendon_stiffness_N / (1000.0 * k.free_length_m + half),
                k.tendon_stiffness_N / (half + k.bend_length_mm))

    def reset(self) -> None:
        self.drum_deg = [0.0, 0.0]
        self.contact_mm = [[0.0, 0.0], [0.0, 0.0]]  # per knob: pulling rope, antagonist
        self.bend_rad = [0.0, 0.0]
        self.set_mm = [[0.0, 0.0], [0.0, 0.0]]
        self.tensions_N = [[0.0, 0.0], [0.0, 0.0]]  # drum-end tensions
        self._drum_torque_Nm = [0.0, 0.0]
        self._mesh_slide = [0.0, 0.0]
        self._brake_slide = [0.0, 0.0]
        self._knob_deg = [0.0, 0.0]

    def reshape(self, **changes: Any) -> None:
        """Shape changes mid-run: ``slack_delta_mm=((pos, neg), (pos, neg))`` (ropes slip in
        their crimps) and ``sheath_curvature_deg`` (the shaft's path changes)."""
        for name, value in changes.items():
            if name == "slack_delta_mm":
                self.slack_delta_mm = [[float(v) for v in pair] for pair in value]
            elif name == "sheath_curvature_deg":
                if not float(value) >= 0.0:
                    raise ValueError(f"sheath_curvature_deg must be >= 0, got {value!r}")
                self.sheath_curvature_deg = float(value)
            else:
                raise ValueError(f"cyclopebax cannot reshape {name!r}")

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q = step_inputs(dt_s, knob_deg)
        bends = (self.bend_rad[0], self.bend_rad[1])
        total = math.hypot(*bends)
        torque = [0.0, 0.0]
        for j in (0, 1):
            other = 1 - j
            takeup_other = (self.cross_takeup_share
                            * section_at(self._tables[other], bends[other])[2])
            torque[j] = self._step_knob(j, q[j], total, takeup_other)
        tip = np.array([self.bend_rad[0] / _DEG, self.bend_rad[1] / _DEG])
        return PlantStep(tip, np.array(torque))

    def _drum(self, j: int, q_deg: float) -> float:
        """The drum angle (deg) after the reducer: on the loaded flank, or held by its bushing."""
        k = self.knobs[j]
        n = k.reducer_ratio
        tau = self._drum_torque_Nm[j]
        half = 0.5 * k.lost_motion_deg / n
        twist = mesh_twist_deg(tau / n, k.mesh_twist_deg, k.mesh_ref_torque_Nm) / n
        lo = q_deg / n - half - (twist if tau > 0.0 else 0.0)
        hi = q_deg / n + half + (twist if tau < 0.0 else 0.0)
        hold = 1e-3 * k.drum_friction_Nmm
        if tau > hold:
            drum = lo
        elif tau < -hold:
            drum = hi
        else:
            drum = min(max(self.drum_deg[j], lo), hi)
        self.drum_deg[j] = drum
        return drum

    def _step_knob(self, j: int, q_deg: float, total_bend_rad: float,
                   takeup_other_mm: float) -> float:
        k = self.knobs[j]
        k0, k1 = self._k[j]
        table = self._tables[j]
        draw = k.drum_radius_mm * self._drum(j, q_deg) * _DEG
        delta = self.slack_delta_mm[j]
        sets = self.set_mm[j]
        prox_p = draw - k.slack_pos_mm - sets[0] - delta[0]
        prox_a = -draw - k.slack_neg_mm - sets[1] - delta[1]
        wrap = ((k.sheath_wrap_deg + self.sheath_curvature_deg) * _DEG
                + SECTION_LUMEN_FRICTION_SHARE * total_bend_rad)
        g_in, g_out = grips(k.sheath_friction, k.lay_asymmetry, wrap)
        r = k.tendon_offset_mm
        y_p0, y_a0 = self.contact_mm[j]
        drag = k.sheath_drag_N

        def balance(bend: float) -> tuple[float, float, tuple[float, ...]]:
            moment, stiff, takeup, slope = section_at(table, bend)
            arm_p, arm_a = r - slope, -r - slope
            out_p = lumen_contact(y_p0, prox_p, r * bend - takeup - takeup_other_mm, k0, k1,
                                  g_in, g_out, drag)
            out_a = lumen_contact(y_a0, prox_a, -r * bend - takeup - takeup_other_mm, k0, k1,
                                  g_in, g_out, drag)
            h = out_p[2] * arm_p + out_a[2] * arm_a - moment
            dh = out_p[3] * arm_p * arm_p + out_a[3] * arm_a * arm_a - stiff
            return h, dh, (*out_p, *out_a)

        bend = self.bend_rad[j]
        lo, hi = -math.inf, math.inf
        for _ in range(60):
            h, dh, outs = balance(bend)
            if h > 0.0:
                lo = bend
            else:
                hi = bend
            if abs(h) < 1e-7:
                break
            step = -h / dh if dh < 0.0 else (0.05 if h > 0.0 else -0.05)
            step = max(-0.2, min(0.2, step))
            nxt = bend + step
            if not lo < nxt < hi:
                nxt = 0.5 * (lo + hi) if math.isfinite(lo) and math.isfinite(hi) else nxt
            if abs(nxt - bend) < 1e-12:
                break
            bend = nxt
        self.bend_rad[j] = bend
        y_p, t0_p, _, _, y_a, t0_a, _, _ = outs
        self.contact_mm[j] = [y_p, y_a]
        self.tensions_N[j] = [t0_p, t0_a]
        for side, t0 in enumerate((t0_p, t0_a)):
            limit = k.yield_tension_N + k.set_hardening_N_per_mm * sets[side]
            if t0 > limit:
                sets[side] += (t0 - limit) / (k.set_hardening_N_per_mm + k0)
        tau = 1e-3 * k.drum_radius_mm * (t0_p - t0_a)
        self._drum_torque_Nm[j] = tau
        return self._knob_torque(j, q_deg, tau)

    def _knob_torque(self, j: int, q_deg: float, drum_torque_Nm: float) -> float:
        """The drum's load through the reducer's load-dependent mesh loss, plus the brake."""
        k = self.knobs[j]
        move = q_deg - self._knob_deg[j]
        self._knob_deg[j] = q_deg
        mesh = min(1.0, max(-1.0, self._mesh_slide[j] + move / k.mesh_presliding_deg))
        brake = min(1.0, max(-1.0, self._brake_slide[j] + move / k.handle_presliding_deg))
        self._mesh_slide[j], self._brake_slide[j] = mesh, brake
        n = k.reducer_ratio
        loss = (k.mesh_friction * abs(drum_torque_Nm) + 1e-3 * k.drum_friction_Nmm) / n
        return drum_torque_Nm / n + loss * mesh + k.handle_friction_Nm * brake


def make_cyclopebax_plant(knobs: Sequence[dict[str, Any] | CycloPebaxKnob] | None = None,
                          sheath_curvature_deg: float = 0.0,
                          coupling: float = 0.0) -> CycloPebaxPlant:
    """A cyclopebax catheter: ``knobs=[{...}, {...}]`` overrides the nominal constants;
    ``coupling`` adds that many times the other plane's take-up to every rope (0: as written)."""
    if knobs is None:
        knobs = NOMINAL_KNOBS
    if len(knobs) != 2:
        raise PlantLoadError(f"cyclopebax takes 2 knobs, got {len(knobs)}")
    return CycloPebaxPlant([knob_from(v, n) for v, n in zip(knobs, NOMINAL_KNOBS, strict=True)],
                           sheath_curvature_deg, coupling)
