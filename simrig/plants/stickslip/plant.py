"""The stick-slip plant: two knobs, each a :class:`KnobRing`, coupled through the tip's bend."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantStep, step_inputs
from simrig.plants.stickslip.params import (
    NOMINAL_KNOBS,
    StickSlipKnobParams,
    StickSlipParamError,
)
from simrig.plants.stickslip.ring import KnobRing


class StickSlipPlant:
    """Polymer tendons in Karnopp stick-slip sheath nodes, a cable-driven braked drum per knob,
    a pseudo-rigid-body tip with its weight. Knob 1 bends the tip in plane 1, knob 2 in plane 2;
    each knob's tendons rub round the whole bent section (both planes' bend): the coupling."""

    def __init__(self, knobs: Sequence[StickSlipKnobParams] = NOMINAL_KNOBS,
                 sheath_curvature_deg: float = 0.0) -> None:
        if len(knobs) != 2:
            raise StickSlipParamError(f"knobs must hold 2 knobs, got {len(knobs)}")
        self.knobs = tuple(knobs)
        self.rings = [KnobRing(k, sheath_curvature_deg) for k in self.knobs]
        self.sheath_curvature_deg = sheath_curvature_deg

    def reset(self) -> None:
        """Straight, unloaded; a reshape applied earlier stays."""
        for ring in self.rings:
            ring.reset()

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q0, q1 = step_inputs(dt_s, knob_deg)
        a, b = self.rings
        bend_a, bend_b = a.bend_rad, b.bend_rad  # the coupling uses the last step's bends
        a.step(dt_s, math.radians(q0), bend_b)
        b.step(dt_s, math.radians(q1), bend_a)
        return PlantStep(np.array([math.degrees(a.bend_rad), math.degrees(b.bend_rad)]),
                         np.array([a.torque_Nm, b.torque_Nm]))

    def reshape(self, slack_delta_mm: Any = None, sheath_curvature_deg: Any = None) -> None:
        """Change the shape mid-run: ``slack_delta_mm=((pos, neg), (pos, neg))`` lengthens the
        tendons at their crimps, ``sheath_curvature_deg`` lays the shaft in a bend."""
        if slack_delta_mm is not None:
            try:
                pairs = [(float(p), float(n)) for p, n in slack_delta_mm]
            except (TypeError, ValueError):
                raise StickSlipParamError("slack_delta_mm must be ((pos, neg), (pos, neg)) in mm, "
                                          f"got {slack_delta_mm!r}") from None
            if len(pairs) != 2 or not all(math.isfinite(v) for pr in pairs for v in pr):
                raise StickSlipParamError("slack_delta_mm must be ((pos, neg), (pos, neg)) in mm, "
                                          f"got {slack_delta_mm!r}")
            for ring, (pos, neg) in zip(self.rings, pairs, strict=True):
                ring.set_slack_delta(pos, neg)
        if sheath_curvature_deg is not None:
            try:
                curvature = float(sheath_curvature_deg)
                for ring in self.rings:
                    ring.set_curvature(curvature)
            except (TypeError, ValueError):
                raise StickSlipParamError("sheath_curvature_deg must be a finite angle >= 0, "
                                          f"got {sheath_curvature_deg!r}") from None
            self.sheath_curvature_deg = curvature

    @property
    def tension_N(self) -> list[list[float]]:
        """Per knob, the tension of every segment (diagnostics)."""
        out = []
        for ring in self.rings:
            t, _, _ = ring._tensions(ring.y, (1.0, 1.0), (1.0, 1.0))
            out.append(t)
        return out


def make_stickslip_plant(knobs: Sequence[Mapping[str, float] | StickSlipKnobParams] | None = None,
                         sheath_curvature_deg: float = 0.0) -> StickSlipPlant:
    """Factory for ``sim.plant: simrig.plants.stickslip:make_stickslip_plant``; ``knobs`` are
    two mappings of :class:`StickSlipKnobParams` overrides."""
    if knobs is None:
        return StickSlipPlant(NOMINAL_KNOBS, sheath_curvature_deg)
    if isinstance(knobs, (str, bytes)) or not isinstance(knobs, Sequence) or len(knobs) != 2:
        raise StickSlipParamError(f"knobs must be a list of 2 mappings, got {knobs!r}")
    built = []
    known = set(StickSlipKnobParams.__dataclass_fields__)
    for i, k in enumerate(knobs):
        if isinstance(k, StickSlipKnobParams):
            built.append(k)
            continue
        if not isinstance(k, Mapping):
            raise StickSlipParamError(f"knobs[{i}] must be a mapping of constants, got {k!r}")
        unknown = sorted(str(n) for n in set(k) - known)
        if unknown:
            raise StickSlipParamError(f"knobs[{i}]: unknown parameter {unknown[0]!r}")
        try:
            values = {str(n): float(v) for n, v in k.items()}
        except (TypeError, ValueError):
            raise StickSlipParamError(f"knobs[{i}]: every constant must be a number, "
                                      f"got {dict(k)!r}") from None
        knob = StickSlipKnobParams(**values)
        try:
            knob.check()
        except StickSlipParamError as exc:
            raise StickSlipParamError(f"knobs[{i}].{exc}") from None
        built.append(knob)
    try:
        curvature = float(sheath_curvature_deg)
    except (TypeError, ValueError):
        raise StickSlipParamError(f"sheath_curvature_deg must be a number, got "
                                  f"{sheath_curvature_deg!r}") from None
    return StickSlipPlant(built, curvature)
