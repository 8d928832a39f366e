"""The built-in catheter plant: physics of two antagonistic tendon-sheath pairs.

Per knob, a pulley of radius ``r`` draws in one tendon and pays out its antagonist. Each tendon
has slack between pulley and sheath (the dead zone), is elastic, and runs through a sheath
discretised into elements with capstan friction (stick/slip per element, so the backlash has
curved transitions). At the distal end both tendons act on a bending section made of joints
with stiffness and Coulomb friction; its stiffness straightens the tip when the tendons release.
Equilibrium is solved exactly every step (see :mod:`simrig.plants.capstan.tendon`), so the plant is
quasi-static, stable at any step size and cheap.

The knob torque is the tendon torque plus the handle's own friction (knob bearings, friction
brake). Optional unmodelled effects, all off by default, are described in ``docs/plant.md``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, fields, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.capstan.tendon import (
    TendonGeometry,
    apply_pull,
    residual_m,
    settle_breakaway,
    solve_pull,
)

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class KnobParams:
    """Mechanical constants of one knob's tendon pair (units in the names)."""

    pulley_radius_mm: float = 6.0
    slack_pos_mm: float = 2.0
    """Slack of the tendon pulled by positive knob rotation."""
    slack_neg_mm: float = 2.15
    tendon_offset_mm: float = 2.47
    """Moment arm of the tendons in the bending section."""
    tendon_stiffness_N: float = 6000.0
    """Axial stiffness EA of the tendon."""
    sheath_length_m: float = 1.0
    free_length_m: float = 0.01
    """Tendon length between pulley and sheath entry (no friction)."""
    sheath_friction: float = 0.25
    """Coulomb friction coefficient tendon/sheath."""
    sheath_wrap_deg: float = 480.0
    """Total wrap angle of the tendon in the (straight) sheath: coil helix and lumen contact."""
    routing_wrap_deg: float = 0.0
    """Wrap of the tendon over guide pins in the handle, right after the pulley. The default
    handle runs the tendon straight from the pulley into the sheath; a routed handle (e.g. 360)
    isolates the knob from the sheath, so the motor current no longer shows the backlash
    (docs/plant.md, "Handle routing")."""
    routing_friction: float = 0.25
    """Friction coefficient on the handle guide pins."""
    sheath_drag_N: float = 0.15
    """Tension-independent friction summed over the sheath (preload of the coil sheath, tendon
    bending stiffness in its lumen); it traps some tension when released (residual bend)."""
    bend_stiffness_Nm_per_rad: float = 0.0065
    bend_friction_Nm: float = 0.0006
    """Mean Coulomb friction moment of the bending joints (spread 0.4x..1.6x over the joints)."""
    bend_stiction_ratio: float = 1.0
    """Static over kinetic friction of the bending joints (>= 1; 1 = off): with more, a joint
    breaks loose with a small jump of the tip and of the tendon tension (stick-slip)."""
    handle_friction_Nm: float = 0.012
    """Kinetic friction torque of the knob itself (bearings, friction brake)."""
    handle_stiction_Nm: float = 0.04
    """Friction torque of the knob when it starts to slide after a reversal or a stop."""
    handle_slip_deg: float = 3.0
    """Knob travel over which the handle friction falls from static to kinetic (the friction
    contact renews itself over a characteristic slip distance, as in rate-and-state friction)."""

    def validated(self, where: str) -> KnobParams:
        for f in fields(self):
            value = getattr(self, f.name)
            if not isinstance(value, int | float) or isinstance(value, bool):
                raise PlantLoadError(f"{where}.{f.name} must be a number, got {value!r}")
            if not math.isfinite(value):
                raise PlantLoadError(f"{where}.{f.name} must be finite, got {value!r}")
        positive = (
            "pulley_radius_mm",
            "tendon_offset_mm",
            "tendon_stiffness_N",
            "sheath_length_m",
            "bend_stiffness_Nm_per_rad",
            "handle_slip_deg",
        )
        for name in positive:
            if getattr(self, name) <= 0.0:
                raise PlantLoadError(f"{where}.{name} must be > 0, got {getattr(self, name)!r}")
        if self.bend_stiction_ratio < 1.0:
            raise PlantLoadError(
                f"{where}.bend_stiction_ratio must be >= 1, got {self.bend_stiction_ratio!r}"
            )
        for f in fields(self):
            if f.name not in positive and getattr(self, f.name) < 0.0:
                raise PlantLoadError(
                    f"{where}.{f.name} must be >= 0, got {getattr(self, f.name)!r}"
                )
        return self


# The anterior-posterior and right-left knobs of one catheter differ slightly.
DEFAULT_KNOBS = (
    KnobParams(),
    KnobParams(slack_pos_mm=2.15, slack_neg_mm=1.95, sheath_wrap_deg=450.0, tendon_offset_mm=2.43),
)


@dataclass(frozen=True)
class Effects:
    """Strength of the switchable unmodelled effects; 0 switches an effect off."""

    coupling: float = 0.0
    """Scale of the cross-knob coupling (1.0 = nominal, see the two constants below)."""
    coupling_tendon_twist_deg: float = 8.0
    """Angular misplacement of the tendons from the ideal orthogonal lumens: bending the other
    plane changes their path length in opposite senses, shifting the dead zone linearly."""
    coupling_shortening_mm_per_rad2: float = 0.45
    """Axial shortening of the bending section when bent in the other plane (adds slack to both
    tendons, widening the dead zone quadratically)."""
    rate_dependence: float = 0.0
    """Relative rise of the sheath friction per ``rate_reference_deg_s`` of knob speed
    (viscous drag of the lubricated sheath; the handle guides are unaffected)."""
    rate_reference_deg_s: float = 100.0
    tendon_compliance: float = 0.0
    """Extra tendon compliance relative to the nominal one (1.0 doubles it)."""
    sheath_curvature_deg: float = 0.0
    """Total bend of the sheath path (e.g. 180 for a U loop): adds wrap angle and slack."""
    lumen_clearance_mm: float = 0.35
    """Radial play of the tendon in its lumen; a curved sheath shortens the path by this much
    per radian of curvature."""
    creep_mm_per_N_s: float = 0.0
    """Tendon creep: slack grows by this much per newton of tension per second."""

    def validated(self) -> Effects:
        for f in fields(self):
            value = getattr(self, f.name)
            if not isinstance(value, int | float) or isinstance(value, bool):
                raise PlantLoadError(f"{f.name} must be a number, got {value!r}")
            if not math.isfinite(value) or value < 0.0:
                raise PlantLoadError(f"{f.name} must be finite and >= 0, got {value!r}")
        if self.rate_reference_deg_s <= 0.0:
            raise PlantLoadError(
                f"rate_reference_deg_s must be > 0, got {self.rate_reference_deg_s!r}"
            )
        return self


class _FastPath:
    """What the last full solve of a tendon found, to extend it cheaply while nothing changes.

    While the pulley keeps moving the same way, every element keeps sliding and no further joint
    reaches its threshold, the residual is linear in the proximal tension with a known slope.
    """

    __slots__ = (
        "friction",
        "joint_friction_Nm",
        "joints",
        "limit_N",
        "other_N",
        "rho",
        "slope",
        "t_p",
        "target_m",
    )

    def __init__(
        self,
        rho: float,
        t_p: float,
        target_m: float,
        slope: float,
        limit_N: float,
        other_N: float,
        friction: tuple[FloatArray, FloatArray],
        joint_friction_Nm: FloatArray,
    ) -> None:
        self.rho = rho
        self.t_p = t_p
        self.target_m = target_m
        self.joints: FloatArray | None = None
        self.slope = slope
        self.limit_N = limit_N
        self.other_N = other_N
        self.friction = friction
        self.joint_friction_Nm = joint_friction_Nm


Friction = tuple[FloatArray, FloatArray, FloatArray, FloatArray]


class _Knob:
    """Mutable state and cached constants of one knob."""

    def __init__(self, p: KnobParams, eff: Effects, n_elements: int, n_joints: int) -> None:
        self.p = p
        compliance = (1.0 + eff.tendon_compliance) / p.tendon_stiffness_N
        seg = p.sheath_length_m / n_elements
        spread = np.linspace(0.4, 1.6, n_joints) if n_joints > 1 else np.ones(1)
        self.geom = TendonGeometry(
            free_compliance_m_per_N=p.free_length_m * compliance,
            element_compliance_m_per_N=np.full(n_elements, seg * compliance),
            offset_m=p.tendon_offset_mm * 1e-3,
            joint_stiffness_Nm_per_rad=np.full(n_joints, p.bend_stiffness_Nm_per_rad * n_joints),
        )
        self.kinetic_Nm = p.bend_friction_Nm * spread
        self.static_Nm = self.kinetic_Nm * p.bend_stiction_ratio
        self.has_stiction = p.bend_stiction_ratio > 1.0
        wrap_rad = math.radians(p.sheath_wrap_deg + eff.sheath_curvature_deg)
        # Friction exponent mu * wrap per element; the handle routing sits at the sheath entry.
        self.sheath_exponent = np.full(n_elements, p.sheath_friction * wrap_rad / n_elements)
        self.routing_exponent = np.zeros(n_elements)
        self.routing_exponent[0] = p.routing_friction * math.radians(p.routing_wrap_deg)
        self.radius_m = p.pulley_radius_mm * 1e-3
        curvature_slack_m = eff.lumen_clearance_mm * 1e-3 * math.radians(eff.sheath_curvature_deg)
        self.slack_pos_m = p.slack_pos_mm * 1e-3 + curvature_slack_m
        self.slack_neg_m = p.slack_neg_mm * 1e-3 + curvature_slack_m
        self.n_elements = n_elements
        self.n_joints = n_joints
        self.drag_per_element_N = np.full(n_elements, p.sheath_drag_N / n_elements)
        self.friction_static = self._friction(1.0)
        self.reset()

    def reshape(self, eff: Effects, slack_delta_mm: tuple[float, float]) -> None:
        """A new sheath shape mid-run: wrap and slack change, the tendons keep their tension."""
        p = self.p
        wrap_rad = math.radians(p.sheath_wrap_deg + eff.sheath_curvature_deg)
        self.sheath_exponent = np.full(self.n_elements, p.sheath_friction * wrap_rad
                                       / self.n_elements)
        curvature_slack_m = eff.lumen_clearance_mm * 1e-3 * math.radians(eff.sheath_curvature_deg)
        self.slack_pos_m = (p.slack_pos_mm + slack_delta_mm[0]) * 1e-3 + curvature_slack_m
        self.slack_neg_m = (p.slack_neg_mm + slack_delta_mm[1]) * 1e-3 + curvature_slack_m
        self.friction_static = self._friction(1.0)
        for side in (0, 1):  # cached solutions belong to the old shape
            self._last[side] = None
            self._fast[side] = None

    def _friction(self, sheath_scale: float) -> Friction:
        """(G, H) for pulling and for the mirrored release, sheath friction scaled."""
        gain = np.exp(-np.cumsum(sheath_scale * self.sheath_exponent + self.routing_exponent))
        inv = 1.0 / gain
        h = self.drag_per_element_N
        return gain, gain * np.cumsum(h * inv), inv, inv * np.cumsum(h * gain)

    def reset(self) -> None:
        self.tension_N = np.zeros((2, self.n_elements))
        self.joints_rad = np.zeros(self.n_joints)
        self.joint_dir = np.zeros(self.n_joints)
        """Direction each joint slid in during the last step (0: stuck, static friction)."""
        self.tip_rad = 0.0
        self.knob_rad: float | None = None
        self.handle_dir = 0.0
        self.handle_slip_deg = 0.0
        # Per tendon (0: "+", 1: "-"), plain floats for speed: proximal tension, distal tension,
        # stretch (free segment + sheath), creep.
        self.proximal = [0.0, 0.0]
        self.distal = [0.0, 0.0]
        self.stretch = [0.0, 0.0]
        self.creep_m = [0.0, 0.0]
        self._last: list[tuple[float, float, FloatArray] | None] = [None, None]
        self._fast: list[_FastPath | None] = [None, None]

    def step(
        self, dt_s: float, knob_rad: float, other_tip_rad: float, eff: Effects
    ) -> tuple[float, float]:
        """Advance to ``knob_rad``; returns (tip angle rad, knob torque Nm)."""
        prev = knob_rad if self.knob_rad is None else self.knob_rad
        speed = (knob_rad - prev) / dt_s if dt_s > 0.0 else 0.0
        self.knob_rad = knob_rad
        friction = self.friction_static
        if eff.rate_dependence > 0.0:
            rel = eff.rate_dependence * abs(math.degrees(speed)) / eff.rate_reference_deg_s
            friction = self._friction(1.0 + rel)

        slack_pos = self.slack_pos_m + self.creep_m[0]
        slack_neg = self.slack_neg_m + self.creep_m[1]
        if eff.coupling > 0.0:
            rb = self.geom.offset_m
            twist = rb * math.sin(math.radians(eff.coupling_tendon_twist_deg)) * other_tip_rad
            short = eff.coupling_shortening_mm_per_rad2 * 1e-3 * other_tip_rad**2
            slack_pos += eff.coupling * (short - twist)
            slack_neg += eff.coupling * (short + twist)

        before = self.joints_rad
        draw_in = self.radius_m * knob_rad
        self._solve_tendon(0, 1.0, draw_in - slack_pos, friction)
        self._solve_tendon(1, -1.0, -draw_in - slack_neg, friction)
        if self.has_stiction:
            if self.joints_rad is not before:
                self.joint_dir = np.sign(self.joints_rad - before)
            elif self.joint_dir.any():
                self.joint_dir = np.zeros(self.n_joints)

        if eff.creep_mm_per_N_s > 0.0 and dt_s > 0.0:
            rate = eff.creep_mm_per_N_s * 1e-3 * dt_s
            self.creep_m = [
                self.creep_m[0] + rate * self.proximal[0],
                self.creep_m[1] + rate * self.proximal[1],
            ]
        torque = self.radius_m * (self.proximal[0] - self.proximal[1])
        torque += self._handle_friction_Nm(math.degrees(knob_rad - prev), math.degrees(speed))
        return self.tip_rad, torque

    def _handle_friction_Nm(self, step_deg: float, speed_deg_s: float) -> float:
        """Knob friction: static after a reversal or stop, kinetic after some slip."""
        p = self.p
        if step_deg == 0.0:
            self.handle_slip_deg = 0.0
        elif (step_deg > 0.0) != (self.handle_dir > 0.0):
            self.handle_dir = 1.0 if step_deg > 0.0 else -1.0
            self.handle_slip_deg = abs(step_deg)
        else:
            self.handle_slip_deg += abs(step_deg)
        level = p.handle_friction_Nm + (p.handle_stiction_Nm - p.handle_friction_Nm) * math.exp(
            -self.handle_slip_deg / p.handle_slip_deg
        )
        return level * math.tanh(speed_deg_s / 0.2)

    def _solve_tendon(self, side: int, sign: float, target_m: float, friction: Friction) -> None:
        """Bring one tendon (``sign`` +1: pulled by positive rotation) into equilibrium."""
        other = self.distal[1 - side]
        last = self._last[side]
        if (
            last is not None
            and last[0] == target_m
            and last[1] == other
            and last[2] is self.joints_rad
            and friction is self.friction_static
        ):
            return  # nothing acting on this tendon changed
        if self.proximal[side] == 0.0 and (
            self.stretch[side] + sign * self.geom.offset_m * self.tip_rad >= target_m
        ):
            pass  # slack, and staying slack
        elif not self._extend_fast(side, sign, target_m, other, friction):
            self._fast[side] = None
            self._full_solve(side, sign, target_m, other, friction)
        self._last[side] = (target_m, other, self.joints_rad)
        fast = self._fast[side]
        if fast is not None:
            fast.joints = self.joints_rad

    def _store(
        self, side: int, rho: float, sign: float, t_p: float, prof: FloatArray, jnt: FloatArray
    ) -> None:
        """Write a pull-frame solution back into the knob's state."""
        self.proximal[side] = rho * t_p
        row = rho * prof
        self.tension_N[side] = row
        self.distal[side] = float(row[-1])
        self.joints_rad = (sign * rho) * jnt
        self.tip_rad = (sign * rho) * float(jnt.sum())

    def _full_solve(
        self, side: int, sign: float, target_m: float, other: float, friction: Friction
    ) -> None:
        tension = self.tension_N[side]
        joints = sign * self.joints_rad
        t_p = self.proximal[side]
        f0 = residual_m(self.geom, tension, t_p, joints, target_m)
        if f0 == 0.0 or (t_p == 0.0 and f0 > 0.0):
            return  # in equilibrium, or slack and staying slack
        rho = 1.0 if f0 < 0.0 else -1.0
        g, h = (friction[0], friction[1]) if rho > 0.0 else (friction[2], friction[3])
        # A joint already sliding this way needs only kinetic friction, a stuck one static.
        sliding = self.joint_dir == sign * rho if self.has_stiction else None
        mf = (
            self.kinetic_Nm
            if sliding is None
            else np.where(sliding, self.kinetic_Nm, self.static_Nm)
        )
        other_r = rho * other
        sol = solve_pull(self.geom, g, h, rho * tension, rho * joints, mf, other_r, rho * target_m)
        t_new, prof, jnt = sol.proximal_N, sol.tension_N, sol.joints_rad
        if rho * t_new < 0.0:  # a tendon cannot push: it goes slack
            t_new = 0.0
            prof, jnt = apply_pull(self.geom, g, h, rho * tension, rho * joints, mf, other_r, 0.0)
        elif sol.all_slip:
            freed = None if sliding is None else (jnt != rho * joints) & ~sliding
            if freed is not None and freed.any():
                t_new, prof, jnt = settle_breakaway(
                    self.geom, g, h, jnt, freed, self.kinetic_Nm, other_r, rho * target_m
                )
            else:
                fast_mf = np.where(jnt != rho * joints, self.kinetic_Nm, mf)
                self._fast[side] = _FastPath(
                    rho, t_new, target_m, sol.slope_m_per_N, sol.limit_N, other, (g, h), fast_mf
                )
        self._store(side, rho, sign, t_new, prof, jnt)
        self.stretch[side] = self.proximal[side] * self.geom.free_compliance_m_per_N + float(
            self.tension_N[side] @ self.geom.element_compliance_m_per_N
        )

    def _extend_fast(
        self, side: int, sign: float, target_m: float, other: float, friction: Friction
    ) -> bool:
        fast = self._fast[side]
        if (
            fast is None
            or fast.joints is not self.joints_rad
            or friction is not self.friction_static
            or other != fast.other_N
        ):
            return False
        rho = fast.rho
        t_new = fast.t_p + rho * (target_m - fast.target_m) / fast.slope
        if not (fast.t_p < t_new <= fast.limit_N) or rho * t_new < 0.0:
            return False  # reversal, a new threshold, or the tendon goes slack: solve in full
        g, h = fast.friction
        prof = t_new * g - h
        k = self.geom.joint_stiffness_Nm_per_rad
        turned = (self.geom.offset_m * (float(prof[-1]) - rho * other) - fast.joint_friction_Nm) / k
        jnt = np.maximum((sign * rho) * self.joints_rad, turned)
        self._store(side, rho, sign, t_new, prof, jnt)
        # The residual is zero at the solution: stretch = draw-in - distal travel.
        self.stretch[side] = target_m - sign * self.geom.offset_m * self.tip_rad
        fast.t_p = t_new
        fast.target_m = target_m
        return True


class TendonSheathPlant:
    """Two knobs (phi1 anterior-posterior, phi2 right-left), each an antagonistic tendon pair.

    Implements :class:`simrig.plant.Plant`. Build it with :func:`make_tendon_sheath_plant`.
    """

    def __init__(
        self,
        knobs: Sequence[KnobParams] = DEFAULT_KNOBS,
        effects: Effects | None = None,
        n_elements: int = 24,
        n_joints: int = 6,
    ) -> None:
        if len(knobs) != 2:
            raise PlantLoadError(f"knobs must list 2 knobs, got {len(knobs)}")
        self.knob_params = tuple(k.validated(f"knobs[{i}]") for i, k in enumerate(knobs))
        self.effects = (effects or Effects()).validated()
        if not isinstance(n_elements, int) or not 2 <= n_elements <= 400:
            raise PlantLoadError(f"n_elements must be an integer in 2..400, got {n_elements!r}")
        if not isinstance(n_joints, int) or not 1 <= n_joints <= 50:
            raise PlantLoadError(f"n_joints must be an integer in 1..50, got {n_joints!r}")
        self._knobs = [_Knob(p, self.effects, n_elements, n_joints) for p in self.knob_params]

    def reset(self) -> None:
        """Straight tip, slack tendons, no creep."""
        for k in self._knobs:
            k.reset()

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        """Move the knobs to ``knob_deg`` (degrees, shape (2,)) and settle."""
        q0, q1 = step_inputs(dt_s, knob_deg)
        k0, k1 = self._knobs
        tips = (k0.tip_rad, k1.tip_rad)
        tip0, tau0 = k0.step(dt_s, math.radians(q0), tips[1], self.effects)
        tip1, tau1 = k1.step(dt_s, math.radians(q1), tips[0], self.effects)
        return PlantStep(
            tip_deg=np.array([math.degrees(tip0), math.degrees(tip1)]),
            knob_torque_Nm=np.array([tau0, tau1]),
        )

    def reshape(self, sheath_curvature_deg: float | None = None,
                slack_delta_mm: Sequence[tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
                ) -> None:
        """Change the sheath's shape now (``simrig.scenario``): its total bend, and per knob the
        tendons' slack (pos, neg) relative to the built values; the state carries over."""
        eff = self.effects
        if sheath_curvature_deg is not None:
            eff = replace(eff, sheath_curvature_deg=float(sheath_curvature_deg)).validated()
        if len(slack_delta_mm) != 2:
            raise ValueError(f"slack_delta_mm must list 2 knobs, got {len(slack_delta_mm)}")
        self.effects = eff
        for knob, (d_pos, d_neg) in zip(self._knobs, slack_delta_mm, strict=True):
            knob.reshape(eff, (float(d_pos), float(d_neg)))

    def tendon_tension_N(self) -> NDArray[np.float64]:
        """Proximal tension of the four tendons, shape (2 knobs, 2 sides: pos, neg)."""
        return np.array([k.proximal for k in self._knobs])


_EFFECT_NAMES = {f.name for f in fields(Effects)}
_KNOB_NAMES = {f.name for f in fields(KnobParams)}


def make_tendon_sheath_plant(
    knobs: Sequence[Mapping[str, Any]] | None = None,
    n_elements: int = 24,
    n_joints: int = 6,
    unit_variation: float = 0.0,
    seed: int = 0,
    **effects: float,
) -> TendonSheathPlant:
    """Build the default plant; keyword parameters switch the unmodelled effects on.

    ``knobs`` overrides per-knob constants (``[{"slack_pos_mm": 2.5}, {}]``), the other keywords
    are :class:`Effects` fields. ``unit_variation`` (e.g. 0.1 = +-10 %) draws catheter-to-catheter
    variation of slacks, friction and stiffness from ``seed``, so a seed names one catheter.
    """
    unknown = sorted(set(effects) - _EFFECT_NAMES)
    if unknown:
        raise PlantLoadError(
            f"unknown plant parameter {unknown[0]!r}; known: "
            f"knobs, n_elements, n_joints, unit_variation, seed, {', '.join(sorted(_EFFECT_NAMES))}"
        )
    overrides = list(knobs) if knobs is not None else [{}, {}]
    if len(overrides) != 2:
        raise PlantLoadError(f"knobs must list 2 knobs, got {len(overrides)}")
    if not isinstance(unit_variation, int | float) or not 0.0 <= unit_variation < 0.5:
        raise PlantLoadError(f"unit_variation must be in [0, 0.5), got {unit_variation!r}")
    rng = np.random.default_rng(seed)
    built = []
    for i, (base, over) in enumerate(zip(DEFAULT_KNOBS, overrides, strict=True)):
        if not isinstance(over, Mapping):
            raise PlantLoadError(f"knobs[{i}] must be a mapping, got {over!r}")
        bad = sorted(set(over) - _KNOB_NAMES)
        if bad:
            raise PlantLoadError(f"knobs[{i}]: unknown parameter {bad[0]!r}")
        params = replace(base, **dict(over)).validated(f"knobs[{i}]")
        if unit_variation > 0.0:
            varied = {
                name: asdict(params)[name] * (1.0 + unit_variation * rng.uniform(-1.0, 1.0))
                for name in (
                    "slack_pos_mm",
                    "slack_neg_mm",
                    "sheath_friction",
                    "bend_stiffness_Nm_per_rad",
                    "bend_friction_Nm",
                    "handle_friction_Nm",
                )
            }
            params = replace(params, **varied)
        built.append(params)
    try:
        eff = Effects(**effects)
    except TypeError as exc:  # pragma: no cover - names are checked above
        raise PlantLoadError(str(exc)) from exc
    return TendonSheathPlant(built, eff, n_elements=n_elements, n_joints=n_joints)
