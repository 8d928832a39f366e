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
from dataclasses import asdict, fields, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.capstan.knob import _Knob
from simrig.plants.capstan.params import DEFAULT_KNOBS, Effects, KnobParams

__all__ = ["DEFAULT_KNOBS", "Effects", "KnobParams", "TendonSheathPlant",
           "make_tendon_sheath_plant"]


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
