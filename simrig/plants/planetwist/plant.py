"""The planetwist plant: a planetary handle stage, twist-coupled strands in swivel crimps, a
lumped lumen contact per rope, a stiffening section and blood flow on the tip.

Per plane the section's bend is the state; one rope of the pair carries the load (the other
keeps the drag-level tension its sliding contact leaves). The bend moves only when the loaded
rope's lumen contact slides: forward when the drum's draw reaches what the rope chain needs at
the current bend (slack, path a x bend, the strand's stretch with its swivel, the proximal
rope's stretch and the stage's wind-up at the contact's forward tension), backward when the draw
falls below what it needs at the backward tension. Each is one monotone scalar equation in the
bend, solved by a safeguarded Newton iteration; between the two the contact sticks and the tip
holds (the backlash). The stage's tooth clearance is a play between knob and drum that shows
only when no rope is loaded (it widens the dead zone).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.planetwist.laws import (
    KnobConstants,
    contact_factor,
    flow_moment_Nmm,
    knob_constants,
    proximal_give_mm,
    proximal_tension_N,
    section_moment_Nmm,
    strand_stretch,
)
from simrig.plants.planetwist.params import NOMINAL_KNOBS, PlanetTwistKnob, check_knob

SPEED_SCALE_DEG_S = 0.5
"""Knob speed over which friction and the stage's driving/back-driven loss turn round."""
MAX_BEND_RAD = math.radians(200.0)
_NEWTON_STEPS = 12
_TOLERANCE_MM = 1e-9


class PlanetTwistPlant:
    """Two knobs, two planes; see the module docstring. Implements :class:`Plant`."""

    def __init__(self, knobs: Sequence[PlanetTwistKnob], sheath_curvature_deg: float = 0.0,
                 heart_rate_hz: float = 1.2) -> None:
        self.knobs = tuple(knobs)
        self._k = tuple(knob_constants(k) for k in self.knobs)
        self.sheath_curvature_deg = sheath_curvature_deg
        self.heart_rate_hz = heart_rate_hz
        self._slack = [[k.slack_pos_mm, k.slack_neg_mm] for k in self.knobs]
        self.reset()

    def reset(self) -> None:
        self.t_s = 0.0
        self.bend_rad = [0.0, 0.0]
        self.tip_rad = [0.0, 0.0]
        """The section's bend plus the shaft's bend under the ropes' eccentric compression."""
        self.side = [0, 0]
        """+1: the + rope carries the load, -1: the - rope, 0: both released (dead zone)."""
        self._play_rad = [0.0, 0.0]
        self.twist_rad_mm = [[0.0, 0.0], [0.0, 0.0]]
        """The swivels' strand twist per length, per plane (+ rope, - rope)."""
        self.proximal_N = [[0.0, 0.0], [0.0, 0.0]]
        self.distal_N = [[0.0, 0.0], [0.0, 0.0]]
        self._carrier_rad: list[float | None] = [None, None]
        self._knob_deg: list[float | None] = [None, None]
        self._drive = [0.0, 0.0]

    def reshape(self, **changes: Any) -> None:
        """``slack_delta_mm=((d+, d-), (d+, d-))`` (mm added per rope) and/or
        ``sheath_curvature_deg`` (wrap added at every lumen contact)."""
        unknown = sorted(set(changes) - {"slack_delta_mm", "sheath_curvature_deg"})
        if unknown:
            raise PlantLoadError(f"planetwist cannot reshape {', '.join(unknown)}")
        if "slack_delta_mm" in changes:
            for plane, deltas in enumerate(changes["slack_delta_mm"]):
                for rope, delta in enumerate(deltas):
                    self._slack[plane][rope] = max(0.0, self._slack[plane][rope] + float(delta))
        if "sheath_curvature_deg" in changes:
            self.sheath_curvature_deg = _curvature(changes["sheath_curvature_deg"])

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        q = step_inputs(dt_s, knob_deg)
        self.t_s += dt_s
        bends = list(self.bend_rad)
        torque = [0.0, 0.0]
        extra_wrap = math.radians(self.sheath_curvature_deg)
        for i in (0, 1):
            torque[i] = self._plane_step(i, dt_s, q[i], bends[1 - i], extra_wrap)
        return PlantStep(np.degrees(np.array(self.tip_rad)), np.array(torque))

    # -- one plane --------------------------------------------------------------------------
    def _plane_step(self, i: int, dt_s: float, q_deg: float, other_rad: float,
                    extra_wrap_rad: float) -> float:
        k = self._k[i]
        carrier = math.radians(q_deg) / k.ratio
        last = self._carrier_rad[i]
        side = self.side[i]
        play = self._play_rad[i]
        if last is not None:
            play = min(k.play_rad, max(-k.play_rad, play + carrier - last))
        self._carrier_rad[i] = carrier
        m = contact_factor(k, extra_wrap_rad)
        drag_tension = k.drag_N / (1.0 - m)
        flow = flow_moment_Nmm(k, self.t_s, self.bend_rad[i], self.heart_rate_hz)
        free = flow / k.bend_Nmm_rad
        ctx = _Context(k, m, drag_tension, flow, other_rad,
                       0.5 * k.takeup * k.arm_mm * other_rad * other_rad, self._slack[i],
                       self.twist_rad_mm[i])
        if side != 0 and side * play < k.play_rad:
            play = self._pull_drum(ctx, side, carrier, play, side * self.bend_rad[i])
        self._play_rad[i] = play
        draw = k.drum_mm * (carrier - play)
        bend, side, branch = self.bend_rad[i], self.side[i], 0
        if side != 0:
            sb = max(side * bend, side * free)
            d = side * draw
            ahead = ctx.need(side, sb, 1)
            if d >= ahead[0]:
                bend, branch = side * ctx.solve(side, sb, MAX_BEND_RAD, d, 1, ahead), 1
            else:
                back = ctx.need(side, sb, -1)
                if d <= back[0]:
                    if d <= ctx.need(side, side * free, -1)[0]:
                        side, bend = 0, free
                    else:
                        bend = side * ctx.solve(side, side * free, sb, d, -1, back)
                        branch = -1
        if side == 0:
            bend = free
            for s in (1, -1):
                ahead = ctx.need(s, s * free, 1)
                if s * draw >= ahead[0]:
                    side, branch = s, 1
                    bend = s * ctx.solve(s, s * free, MAX_BEND_RAD, s * draw, 1, ahead)
                    break
        self.bend_rad[i], self.side[i] = bend, side
        carrier_Nmm = self._commit(i, ctx, draw, bend, side, branch)
        if abs(play) < k.play_rad - 1e-12:
            carrier_Nmm = 0.0  # the drum floats in the play: the bearing holds the rope
        return self._knob_torque_Nm(i, k, dt_s, q_deg, carrier_Nmm)

    @staticmethod
    def _pull_drum(ctx: _Context, side: int, carrier: float, play: float, bend: float
                   ) -> float:
        """Where the loaded rope leaves the drum inside the stage's play: it pulls the drum
        toward the loaded flank while its proximal tension beats the drum's bearing friction
        (so a released rope lets the play open at a reversal: the tip holds, the torque is
        gone)."""
        k = ctx.k
        tension, _ = ctx.distal(side, bend)
        stretch, _, _ = strand_stretch(k, tension, ctx.twist[0 if side > 0 else 1])
        rest_mm = (ctx.slack[0 if side > 0 else 1] + k.arm_mm * bend + ctx.takeup_mm + stretch
                   + proximal_give_mm(k, k.bearing_Nmm / k.drum_mm)[0])
        held = side * (carrier - rest_mm * side / k.drum_mm)
        return side * min(k.play_rad, max(side * play, held))

    def _commit(self, i: int, ctx: _Context, draw: float, bend: float, side: int,
                branch: int) -> float:
        """Swivels and tensions at the new bend; the carrier torque (N mm)."""
        k, m = ctx.k, ctx.m
        for r, s in enumerate((1, -1)):
            if s == side:
                tension, _ = ctx.distal(s, s * bend)
            else:
                tension = ctx.drag_tension
            stretch, _, self.twist_rad_mm[i][r] = strand_stretch(k, tension,
                                                                 self.twist_rad_mm[i][r])
            high = ((1.0 + m) * tension + k.drag_N) / (1.0 - m)
            low = max(0.0, ((1.0 - m) * tension - k.drag_N) / (1.0 + m))
            if s == side and branch == 1:
                proximal = high
            elif s == side and branch == -1:
                proximal = low
            else:
                give = s * draw - ctx.slack[r] - k.arm_mm * s * bend - ctx.takeup_mm - stretch
                proximal = min(high, max(low if s == side else 0.0,
                                         proximal_tension_N(k, give)))
            self.distal_N[i][r], self.proximal_N[i][r] = tension, proximal
        pulls, holds = self.proximal_N[i], self.distal_N[i]
        self.tip_rad[i] = bend + 0.5 * k.shaft_rad_per_N * (pulls[0] + holds[0] - pulls[1]
                                                           - holds[1])
        return k.drum_mm * (pulls[0] - pulls[1])

    def _knob_torque_Nm(self, i: int, k: KnobConstants, dt_s: float, q_deg: float,
                        carrier_Nmm: float) -> float:
        last = self._knob_deg[i]
        self._knob_deg[i] = q_deg
        speed = (q_deg - last) / dt_s if last is not None and dt_s > 0.0 else 0.0
        if speed != 0.0 and carrier_Nmm != 0.0:
            self._drive[i] = math.tanh(math.copysign(speed, carrier_Nmm) / SPEED_SCALE_DEG_S)
        eta = k.efficiency
        loss = 0.5 * (1.0 / eta + eta) + 0.5 * (1.0 / eta - eta) * self._drive[i]
        return (carrier_Nmm / k.ratio * loss / 1000.0
                + k.handle_Nm * math.tanh(speed / SPEED_SCALE_DEG_S))


class _Context:
    """One plane's rope chain at this step (constants, contact factor, flow, other bend)."""

    __slots__ = ("drag_tension", "flow", "k", "m", "other", "slack", "takeup_mm", "twist")

    def __init__(self, k: KnobConstants, m: float, drag_tension: float, flow: float,
                 other: float, takeup_mm: float, slack: list[float], twist: list[float]
                 ) -> None:
        self.k, self.m, self.drag_tension, self.flow = k, m, drag_tension, flow
        self.other, self.takeup_mm, self.slack, self.twist = other, takeup_mm, slack, twist

    def distal(self, side: int, bend: float) -> tuple[float, float]:
        """Distal tension of the loaded rope on ``side`` at its own-side bend, and d/d bend."""
        moment, slope = section_moment_Nmm(self.k, bend, self.other)
        arm = self.k.arm_mm
        return max(0.0, self.drag_tension + (moment - side * self.flow) / arm), slope / arm

    def need(self, side: int, bend: float, branch: int) -> tuple[float, float]:
        """The draw the rope on ``side`` needs at its own-side ``bend`` for its contact to
        slide forward (``branch`` 1) or backward (-1), and its slope (mm/rad)."""
        k, m = self.k, self.m
        tension, dt_db = self.distal(side, bend)
        stretch, compliance, _ = strand_stretch(k, tension, self.twist[0 if side > 0 else 1])
        if branch > 0:
            proximal, dp_dt = ((1.0 + m) * tension + k.drag_N) / (1.0 - m), (1 + m) / (1 - m)
        else:
            proximal = ((1.0 - m) * tension - k.drag_N) / (1.0 + m)
            dp_dt = (1 - m) / (1 + m) if proximal > 0.0 else 0.0
            proximal = max(0.0, proximal)
        give, give_slope = proximal_give_mm(k, proximal)
        draw = (self.slack[0 if side > 0 else 1] + k.arm_mm * bend + self.takeup_mm + stretch
                + give)
        return draw, k.arm_mm + (compliance + give_slope * dp_dt) * dt_db

    def solve(self, side: int, low: float, high: float, target_mm: float, branch: int,
              start: tuple[float, float]) -> float:
        """The own-side bend in [low, high] where :meth:`need` equals ``target_mm``; ``start``
        is :meth:`need` at the end the search starts from (``low`` forward, ``high`` back)."""
        bend = low if branch > 0 else high
        draw, slope = start
        for _ in range(_NEWTON_STEPS):
            move = (draw - target_mm) / slope
            bend = min(high, max(low, bend - move))
            if abs(move) * slope < _TOLERANCE_MM:
                break
            draw, slope = self.need(side, bend, branch)
        return bend


def _curvature(value: Any) -> float:
    curvature = float(value)
    if not (math.isfinite(curvature) and curvature >= 0.0):
        raise PlantLoadError(f"planetwist sheath_curvature_deg must be >= 0, got {value!r}")
    return curvature


def make_planetwist_plant(knobs: Sequence[Mapping[str, Any]] | None = None,
                          sheath_curvature_deg: float = 0.0,
                          heart_rate_hz: float = 1.2) -> PlanetTwistPlant:
    """The planetwist plant; ``knobs`` are two dicts of overrides on the nominal knobs."""
    overrides = list(knobs) if knobs is not None else [{}, {}]
    if len(overrides) != 2:
        raise PlantLoadError(f"planetwist takes 2 knobs, got {len(overrides)}")
    built = []
    for nominal, values in zip(NOMINAL_KNOBS, overrides, strict=True):
        if not isinstance(values, Mapping):
            raise PlantLoadError(f"a planetwist knob must be a mapping, got {values!r}")
        built.append(check_knob({**dataclasses.asdict(nominal), **dict(values)}))
    rate = float(heart_rate_hz)
    if not (math.isfinite(rate) and rate >= 0.0):
        raise PlantLoadError(f"planetwist heart_rate_hz must be >= 0, got {heart_rate_hz!r}")
    return PlanetTwistPlant(built, _curvature(sheath_curvature_deg), rate)
