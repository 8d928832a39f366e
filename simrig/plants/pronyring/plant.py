"""PronyRingPlant: a viscoelastic Pebax section, a pull ring on a compliant bond, PTFE-lined ropes
along a breathing path.

Per bending plane the step finds the section's bend ``theta`` at which the two ropes' distal
tensions balance the section's moment:

    r_t * (T_d,pos(theta) - T_d,neg(theta)) = M(theta)

``M`` is the Prony section (long-term spring plus three relaxing branches), the rope's ring-end
demand is ``r_t * (theta + ring tilt)`` plus the ring's axial set-back and the shaft's bend
under the lumen; each rope's tensions come from :func:`laws.rope_contact` (closed form, stick or
slide). The balance is monotone in ``theta`` (piecewise linear): a Newton iteration kept inside
its bracket finds it in a few steps. The ring rides in the section's lumen: its seat holds the
bend until the imbalance exceeds a friction moment proportional to the ring's axial load. The
planes couple through the shared pull ring (the other plane's moment, one step old, tilts the
ring by the anchors' clocking; all four distal tensions, one step old, push the ring back and
take up every rope, and press its seat). ``coupling`` (0: as written) adds a take-up of both
ropes of a plane by the other plane's bend, ``coupling x offset x other^2 / 2`` (rope lumens set
off their plane: the self-test's coupling case).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.pronyring.laws import (
    capstan_ratio,
    liner_friction,
    prony_moment,
    relax,
    rope_contact,
)
from simrig.plants.pronyring.params import (
    BREATHING_HZ,
    KNOB_SPEED_DEG_S,
    NOMINAL_KNOBS,
    KnobConstants,
    knob_constants,
)

_DEG = math.pi / 180.0


class _Plane:
    """One bending plane's state: the bend, the branches' dashpots, the ropes' centroids."""

    def __init__(self, k: KnobConstants) -> None:
        self.k = k
        length_mm = k.sheath_length_m * 1000.0
        self.proximal_N_per_mm = k.tendon_stiffness_N / (k.contact_fraction * length_mm)
        self.distal_N_per_mm = k.tendon_stiffness_N / ((1.0 - k.contact_fraction) * length_mm)
        self.taus = (k.prony_fast_s, k.prony_mid_s, k.prony_slow_s)
        self.branch_k = (k.prony_fast_Nmm_per_rad, k.prony_mid_Nmm_per_rad,
                         k.prony_slow_Nmm_per_rad)
        self.tilt_cos = math.cos(k.ring_clocking_deg * _DEG)
        self.tilt_sin = math.sin(k.ring_clocking_deg * _DEG)
        self.reset()

    def reset(self) -> None:
        self.theta = 0.0
        self.rests = [0.0, 0.0, 0.0]
        self.z = [0.0, 0.0]
        self.proximal_N = [0.0, 0.0]
        self.distal_N = [0.0, 0.0]
        self.moment_Nmm = 0.0
        self.tilt_rad = 0.0
        self.knob_deg: float | None = None


class PronyRingPlant:
    """A TEE-sized probe: Pebax section with creep, tilting pull ring, PTFE ropes (see module)."""

    def __init__(self, knobs: Sequence[KnobConstants], sheath_curvature_deg: float = 0.0,
                 coupling: float = 0.0) -> None:
        self.knobs = tuple(knobs)
        self.sheath_curvature_deg = sheath_curvature_deg
        self.coupling = coupling
        """Take-up of both ropes by the other plane's bend (mm per mm of offset per rad^2 / 2)."""
        self.slack_delta_mm = [[0.0, 0.0], [0.0, 0.0]]
        self.planes = [_Plane(k) for k in self.knobs]
        self.t_s = 0.0

    def reset(self) -> None:
        """Straight and unloaded; a shape change already applied stays."""
        for p in self.planes:
            p.reset()
        self.t_s = 0.0

    def reshape(self, **changes: Any) -> None:
        """``slack_delta_mm=((pos, neg), (pos, neg))`` adds rope slack; ``sheath_curvature_deg``
        sets the shaft's extra bend (anterior-posterior plane)."""
        for name, value in changes.items():
            if name == "slack_delta_mm":
                self.slack_delta_mm = [[float(value[i][j]) for j in range(2)] for i in range(2)]
            elif name == "sheath_curvature_deg":
                self.sheath_curvature_deg = _finite("sheath_curvature_deg", value)
            else:
                raise PlantLoadError(f"pronyring cannot reshape {name!r}")

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q = step_inputs(dt_s, knob_deg)
        self.t_s += dt_s
        p0, p1 = self.planes
        seat_N = sum(p0.distal_N) + sum(p1.distal_N)
        breath_rad = math.sin(2.0 * math.pi * BREATHING_HZ * self.t_s) * _DEG
        cross = (-p0.tilt_sin * p1.moment_Nmm / p1.k.ring_tilt_Nmm_per_rad,
                 p1.tilt_sin * p0.moment_Nmm / p0.k.ring_tilt_Nmm_per_rad)
        other_rad = (p1.theta, p0.theta)
        tips = [0.0, 0.0]
        torques = [0.0, 0.0]
        for i, plane in enumerate(self.planes):
            k = plane.k
            shaft_bend_rad = (k.breathing_wrap_deg * breath_rad
                              + (self.sheath_curvature_deg * _DEG if i == 0 else 0.0))
            takeup_mm = self.coupling * k.tendon_offset_mm * other_rad[i] ** 2 / 2.0
            tips[i], torques[i] = self._plane_step(
                plane, dt_s, q[i], cross[i], seat_N,
                shaft_bend_rad, self.slack_delta_mm[i], takeup_mm)
        return PlantStep(np.array(tips), np.array(torques))

    def _plane_step(self, plane: _Plane, dt_s: float, knob_deg: float, cross_tilt_rad: float,
                    seat_N: float, shaft_bend_rad: float, slack_delta: Sequence[float],
                    takeup_mm: float = 0.0
                    ) -> tuple[float, float]:
        k = plane.k
        r_t = k.tendon_offset_mm
        setback_mm = seat_N / k.ring_axial_N_per_mm - takeup_mm  # the taken-up rope is shorter
        drum = k.drum_radius_mm * knob_deg * _DEG
        drum_mm = (drum - k.slack_pos_mm - slack_delta[0], -drum - k.slack_neg_mm - slack_delta[1])
        shift_mm = k.shaft_offset_mm * shaft_bend_rad
        wrap_rad = (k.sheath_wrap_deg + abs(self.sheath_curvature_deg)) * _DEG + abs(shaft_bend_rad)
        ratios = [capstan_ratio(liner_friction(k.sheath_friction, plane.proximal_N[j],
                                               k.friction_reference_N,
                                               k.friction_load_exponent), wrap_rad)
                  for j in range(2)]
        branches = tuple(zip(plane.branch_k, plane.taus, plane.rests, strict=True))
        kp, kd = plane.proximal_N_per_mm, plane.distal_N_per_mm
        tilt_c = plane.tilt_cos / k.ring_tilt_Nmm_per_rad

        def balance(theta: float) -> tuple[float, float, Any, Any, float]:
            m, stiff = prony_moment(theta, branches, k.bend_stiffness_Nmm_per_rad, dt_s)
            ring = r_t * (theta + tilt_c * m + cross_tilt_rad)
            a = rope_contact(drum_mm[0], ring + setback_mm + shift_mm, plane.z[0], kp, kd,
                             ratios[0], k.sheath_drag_N)
            b = rope_contact(drum_mm[1], -ring + setback_mm - shift_mm, plane.z[1], kp, kd,
                             ratios[1], k.sheath_drag_N)
            g = r_t * (a.distal_N - b.distal_N) - m
            dring = r_t * (1.0 + tilt_c * stiff)
            dg = r_t * dring * (a.distal_slope_N_per_mm + b.distal_slope_N_per_mm) - stiff
            return g, dg, a, b, m

        theta = plane.theta
        g, dg, a, b, m = balance(theta)
        hold_Nmm = k.ring_friction_mm * seat_N
        if abs(g) > hold_Nmm:  # the ring's seat slides: solve for the bend where it just slides
            target = math.copysign(hold_Nmm, g)
            lo, hi = -math.inf, math.inf
            for _ in range(60):
                r = g - target
                if abs(r) < 1e-9:
                    break
                if r > 0.0:
                    lo = theta
                else:
                    hi = theta
                nxt = theta - r / dg
                if not lo < nxt < hi:
                    nxt = 0.5 * (lo + hi)
                if abs(nxt - theta) < 1e-13:
                    break
                theta = nxt
                g, dg, a, b, m = balance(theta)
        plane.theta = theta
        plane.rests = [relax(r, theta, tau, dt_s) for r, tau in zip(plane.rests, plane.taus,
                                                                     strict=True)]
        plane.z = [a.centroid_mm, b.centroid_mm]
        plane.proximal_N = [a.proximal_N, b.proximal_N]
        plane.distal_N = [a.distal_N, b.distal_N]
        plane.moment_Nmm = m
        plane.tilt_rad = tilt_c * m + cross_tilt_rad
        speed = 0.0 if plane.knob_deg is None or dt_s <= 0.0 else (
            (knob_deg - plane.knob_deg) / dt_s)
        plane.knob_deg = knob_deg
        seal_Nm = k.handle_friction_Nm * math.tanh(speed / KNOB_SPEED_DEG_S)
        torque_Nm = k.drum_radius_mm * (a.proximal_N - b.proximal_N) / 1000.0 + seal_Nm
        return (theta + plane.tilt_rad) / _DEG, torque_Nm


def _finite(name: str, value: Any) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise PlantLoadError(f"pronyring {name} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise PlantLoadError(f"pronyring {name} must be finite, got {value!r}")
    return v


def make_pronyring_plant(knobs: Sequence[dict[str, Any]] | None = None,
                         sheath_curvature_deg: float = 0.0,
                         coupling: float = 0.0) -> PronyRingPlant:
    """The nominal pronyring catheter, each knob's constants overridable by name; ``coupling``
    takes up both ropes of a plane by the other plane's bend (0: as written)."""
    take_up = _finite("coupling", coupling)
    if take_up < 0.0:
        raise PlantLoadError(f"pronyring coupling must be >= 0, got {coupling!r}")
    if knobs is None:
        knobs = [{}, {}]
    if len(knobs) != 2:
        raise PlantLoadError(f"pronyring takes 2 knobs, got {len(knobs)}")
    built = []
    for nominal, given in zip(NOMINAL_KNOBS, knobs, strict=True):
        values = {f: getattr(nominal, f) for f in nominal.__dataclass_fields__}
        values.update(given)
        built.append(knob_constants(values))
    return PronyRingPlant(built, _finite("sheath_curvature_deg", sheath_curvature_deg), take_up)
