"""The twistshaft plant: a TEE-like catheter whose shaft twists and warms up in the patient.

Per knob, a drum pulls one of two antagonistic fibre tendons (toe, unequal slack) through a lumen
with a Hertzian friction contact (``tendon.py``). The four tendons bend one elastic tip section
in two planes; their lumens sit slightly off their planes (extrusion tolerance), so each knob also
bends the other plane a little, and the other plane's bending changes this knob's tendon paths.
Mechanisms a dead-zone/backlash model leaves out, each physical:

- **shaft torsion with wind-up**: the lumens follow a slight helix, so the tendons' tension
  twists the shaft; its rotational friction against the oesophagus holds part of the twist
  (a play on the twist angle) until the tension changes enough; the tip's bending planes turn
  with the twist, which mixes the two planes in proportion to the bend;
- **warm-up in the patient**: from room to body temperature with a time constant of a minute,
  the tip cover softens (more tip per tension) and the liner softens (larger real contact area,
  more friction), so the catheter drifts during the first minutes after insertion;
- **load-dependent friction coefficient** (Hertzian contact: friction ~ normal^(2/3)).

Quasi-static (no inertia): the step is a return mapping on the contacts plus a 2-D Newton on
the tip, so it is stable at any step; only the temperature depends on ``dt_s`` (exact
exponential).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import fields
from typing import Any

import numpy as np

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.twistshaft.params import (
    ShaftParams,
    TwistKnobParams,
    check_knob,
    check_shaft,
)
from simrig.plants.twistshaft.tendon import LumenTendon, wrap_rad

NOMINAL_KNOBS = (TwistKnobParams(), TwistKnobParams())
"""The nominal unit: both knobs alike (the family scatters each constant per knob)."""


class TwistShaftPlant:
    """Two knobs, four tendons, one twisting and warming shaft, one tip bending in two planes."""

    def __init__(self, knobs: Sequence[TwistKnobParams], shaft: ShaftParams) -> None:
        if len(knobs) != 2:
            raise ValueError(f"twistshaft: knobs must list 2 knobs, got {len(knobs)}")
        for k, p in enumerate(knobs):
            check_knob(k, p)
        check_shaft(shaft)
        self.knobs = tuple(knobs)
        self.shaft = shaft
        self._tendons: list[LumenTendon] = []
        self._geom: list[tuple[int, float, float, float, float]] = []
        """Per tendon: knob, drum sign, moment arm (mm), and its lumen's direction (cos, sin)."""
        for k, p in enumerate(knobs):
            proximal_m = p.free_length_m + 0.5 * p.sheath_length_m
            distal_m = 0.5 * p.sheath_length_m + p.bend_length_mm * 1e-3
            plane = 0.0 if k == 0 else 0.5 * math.pi
            err = math.radians(p.lumen_angle_error_deg)
            for sign, slack in ((1.0, p.slack_pos_mm), (-1.0, p.slack_neg_mm)):
                self._tendons.append(LumenTendon(
                    kp_N_mm=p.tendon_stiffness_N / (proximal_m * 1e3),
                    kd_N_mm=p.tendon_stiffness_N / (distal_m * 1e3), toe_mm=p.toe_mm,
                    slack_mm=slack,
                    wrap_rad=wrap_rad(p.sheath_wrap_deg, shaft.sheath_curvature_deg),
                    mu=p.sheath_friction, n=p.friction_exponent, load_N=p.contact_load_N,
                    drag_N=p.sheath_drag_N))
                beta = plane + err + (0.0 if sign > 0 else math.pi)
                self._geom.append((k, sign, p.tendon_offset_mm, math.cos(beta), math.sin(beta)))
        self._bend_Nmm = [p.bend_stiffness_Nm_per_rad * 1e3 for p in knobs]
        self._handle = [(p.handle_friction_Nm, p.handle_presliding_deg) for p in knobs]
        self._helix = [math.sin(math.radians(p.lumen_helix_deg)) for p in knobs]
        self.reset()

    def reset(self) -> None:
        """Straight, unloaded, untwisted, at room temperature (just inserted)."""
        for t in self._tendons:
            t.reset()
        self.temperature_C = self.shaft.start_temperature_C
        self.bend_rad = [0.0, 0.0]
        self.twist_rad = 0.0
        self._handle_anchor_deg = [0.0, 0.0]

    def reshape(self, slack_delta_mm: Sequence[Sequence[float]] | None = None,
                sheath_curvature_deg: float | None = None) -> None:
        """Change the catheter mid-run (``simrig.scenario``): tendon slack grows by
        ``((knob1 +, knob1 -), (knob2 +, knob2 -))`` mm, or the sheath takes a new curvature;
        the contacts, bend, twist and temperature stay where they are."""
        if slack_delta_mm is not None:
            deltas = [float(d) for pair in slack_delta_mm for d in pair]
            if len(deltas) != 4 or not all(math.isfinite(d) for d in deltas):
                raise ValueError(f"slack_delta_mm must be 2 pairs of finite mm, got "
                                 f"{slack_delta_mm!r}")
            for t, d in zip(self._tendons, deltas, strict=True):
                t.slack_mm += d
        if sheath_curvature_deg is not None:
            if not (math.isfinite(sheath_curvature_deg) and sheath_curvature_deg >= 0.0):
                raise ValueError(f"sheath_curvature_deg must be finite and >= 0, got "
                                 f"{sheath_curvature_deg!r}")
            self.shaft = dataclasses.replace(self.shaft, sheath_curvature_deg=sheath_curvature_deg)
            for i, t in enumerate(self._tendons):
                t.wrap_rad = wrap_rad(self.knobs[self._geom[i][0]].sheath_wrap_deg,
                                      sheath_curvature_deg)

    def _thermal(self) -> tuple[float, float]:
        """Tip stiffness factor and liner friction factor at the present temperature."""
        s = self.shaft
        warm = self.temperature_C - s.start_temperature_C
        stiffness = 1.0 - s.bend_softening_per_C * warm
        liner = 1.0 - s.liner_softening_per_C * warm
        return stiffness, liner ** (-2.0 / 3.0)  # Hertzian area ~ (load / modulus)^(2/3)

    def _tip(self, u: list[float], stiffness: float, mu_factor: float) -> None:
        """Solve the tip's two bends so that the tendons' moments meet the tip's stiffness."""
        th = self.bend_rad
        kb0, kb1 = self._bend_Nmm[0] * stiffness, self._bend_Nmm[1] * stiffness
        tendons, geom = self._tendons, self._geom
        best = math.inf
        for _ in range(40):
            f0, f1 = kb0 * th[0], kb1 * th[1]
            j00, j01, j11 = kb0, 0.0, kb1
            for i, t in enumerate(tendons):
                _, _, a, c, s = geom[i]
                td, dtd = t.trial(u[i], a * (c * th[0] + s * th[1]), mu_factor)
                f0 -= a * td * c
                f1 -= a * td * s
                kap = -dtd * a * a
                j00 += kap * c * c
                j01 += kap * c * s
                j11 += kap * s * s
            res = abs(f0) + abs(f1)
            if res < 1e-9:
                return
            det = j00 * j11 - j01 * j01
            d0 = (j11 * f0 - j01 * f1) / det
            d1 = (j00 * f1 - j01 * f0) / det
            scale = 1.0 if res < best else 0.5  # a contact changed state: damp the step
            best = min(best, res)
            th[0] -= scale * d0
            th[1] -= scale * d1
        for i, t in enumerate(tendons):  # the trials must belong to the final bend
            _, _, a, c, s = geom[i]
            t.trial(u[i], a * (c * th[0] + s * th[1]), mu_factor)

    def step(self, dt_s: float, knob_deg: Any) -> PlantStep:
        q0, q1 = step_inputs(dt_s, knob_deg)
        s = self.shaft
        self.temperature_C += (s.body_temperature_C - self.temperature_C) * (
            1.0 - math.exp(-dt_s / s.warm_time_s))
        stiffness, mu_factor = self._thermal()
        q = (q0, q1)
        u = [sign * self.knobs[k].pulley_radius_mm * math.radians(q[k])
             for k, sign, _, _, _ in self._geom]
        self._tip(u, stiffness, mu_factor)
        th = self.bend_rad
        drum = [0.0, 0.0]
        torque_Nmm = 0.0
        for i, t in enumerate(self._tendons):
            k, sign, a, c, sn = self._geom[i]
            t.commit(u[i], a * (c * th[0] + sn * th[1]))
            drum[k] += sign * t.tp_N
            torque_Nmm += a * self._helix[k] * 0.5 * (t.tp_N + t.td_N)
        # the shaft's twist: a play (its rotational friction) around the elastic twist
        target = torque_Nmm * 1e-3 / s.torsion_stiffness_Nm_per_rad
        play = s.torsion_friction_Nm / s.torsion_stiffness_Nm_per_rad
        self.twist_rad = min(max(self.twist_rad, target - play), target + play)
        cp, sp = math.cos(self.twist_rad), math.sin(self.twist_rad)
        tip = np.array([math.degrees(th[0] * cp - th[1] * sp),
                        math.degrees(th[0] * sp + th[1] * cp)])
        torque = np.empty(2)
        for k in range(2):
            fric_Nm, pre_deg = self._handle[k]
            anchor = min(max(self._handle_anchor_deg[k], q[k] - pre_deg), q[k] + pre_deg)
            self._handle_anchor_deg[k] = anchor
            r_mm = self.knobs[k].pulley_radius_mm
            torque[k] = drum[k] * r_mm * 1e-3 + fric_Nm * (q[k] - anchor) / pre_deg
        return PlantStep(tip, torque)


def make_twistshaft_plant(knobs: Sequence[dict[str, float] | TwistKnobParams] | None = None,
                          **shaft: float) -> TwistShaftPlant:
    """The plant from per-knob constants (``knobs=[{...}, {...}]``) and shaft keywords
    (``ShaftParams`` fields, e.g. ``sheath_curvature_deg``, ``warm_time_s``); a bad constant is
    refused in one line naming it (:class:`simrig.plant.PlantLoadError`)."""
    entries = list(knobs) if knobs is not None else list(NOMINAL_KNOBS)
    if len(entries) != 2:
        raise PlantLoadError(f"twistshaft: knobs must list 2 knobs, got {len(entries)}")
    built: list[TwistKnobParams] = []
    try:
        for k, entry in enumerate(entries):
            if isinstance(entry, TwistKnobParams):
                built.append(entry)
            elif isinstance(entry, Mapping):
                unknown = sorted(set(entry) - {f.name for f in fields(TwistKnobParams)})
                if unknown:
                    raise ValueError(f"twistshaft knob {k}: unknown constant {unknown[0]!r}")
                built.append(TwistKnobParams(**entry))
            else:
                raise ValueError(f"twistshaft knob {k}: a mapping of constants, got {entry!r}")
        unknown = sorted(set(shaft) - {f.name for f in fields(ShaftParams)})
        if unknown:
            raise ValueError(f"twistshaft: unknown shaft constant {unknown[0]!r}")
        return TwistShaftPlant(built, ShaftParams(**shaft))
    except ValueError as exc:
        raise PlantLoadError(str(exc)) from None
