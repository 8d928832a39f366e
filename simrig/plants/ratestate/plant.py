"""The ratestate plant: tendons with friction distributed along the shaft, each contact ageing.

Per knob, an antagonistic pair of steel ropes runs from a drum through ``NODES`` lumen contacts
each (wrap from the shaft's curvature profile) to the bending section. A contact sticks
elastically (presliding) until the local friction, ``mu (T_left + T_right) wrap / 2 + drag``,
is reached; its ``mu`` follows Dieterich's ageing law (it grows with the time a contact has
stuck and falls while it slides). A reversal therefore unloads the tendon from the drum
inwards, contact by contact, and the knob-to-tip loop has rounded corners. The tip's links
rub with a friction proportional to the pair's tension. Coupling: the bend of both planes adds
wrap to the distal contacts of every tendon.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from simrig.plant import PlantLoadError, PlantStep, step_inputs
from simrig.plants.ratestate.chain import (
    BUCKLED_SHARE,
    ChainConstants,
    ChainState,
    FloatArray,
    solve,
)
from simrig.plants.ratestate.laws import age_after, aged_friction, wrap_profile_rad
from simrig.plants.ratestate.params import NODES, RateStateKnobParams, knob_params

REFERENCE_CONTACT_LOAD_N = 1.0
"""Load at which a contact has sheared by its ``presliding_mm`` (sets its elastic stiffness)."""
LINK_PRESLIDING_DEG = 0.5
"""Tip rotation over which the links' friction builds up."""


class RateStatePlant:
    """Two knobs, each an antagonistic tendon loop with ``NODES`` ageing contacts per tendon."""

    def __init__(self, knobs: Sequence[RateStateKnobParams], sheath_curvature_deg: float = 0.0
                 ) -> None:
        if not (math.isfinite(sheath_curvature_deg) and sheath_curvature_deg >= 0.0):
            raise PlantLoadError(f"sheath_curvature_deg must be >= 0, got {sheath_curvature_deg!r}")
        self.knobs = tuple(knobs)
        self.sheath_curvature_deg = sheath_curvature_deg
        n, m = NODES, 2 * NODES + 1
        self.tip_node = n
        shape_e, shape_n = (2, m + 1), (2, m)
        k = np.empty(shape_e)
        slack = np.zeros(shape_e)
        ground = np.zeros(shape_n)
        contact = np.empty(shape_n)
        drag = np.empty(shape_n)
        self._wrap = np.zeros(shape_n)
        self._mu0, self._b = np.zeros(shape_n), np.zeros(shape_n)
        self._dc, self._cutoff = np.ones(shape_n), np.ones(shape_n)
        self._link = np.zeros(2)
        self._bend_mu = np.array([p.bend_lumen_friction for p in self.knobs])
        for i, p in enumerate(self.knobs):
            seg_mm = 1000.0 * p.sheath_length_m / n
            half = 0.5 * seg_mm
            lengths = np.full(m + 1, seg_mm)
            lengths[[0, m]] = 1000.0 * p.free_length_m + half
            lengths[[n, n + 1]] = half + p.bend_length_mm
            k[i] = p.tendon_stiffness_N / lengths
            slack[i, 0], slack[i, m] = p.slack_pos_mm, p.slack_neg_mm
            r_t = p.tendon_offset_mm
            ground[i, n] = 1000.0 * p.bend_stiffness_Nm_per_rad / r_t**2
            contact[i] = REFERENCE_CONTACT_LOAD_N / p.presliding_mm
            contact[i, n] = REFERENCE_CONTACT_LOAD_N / (r_t * math.radians(LINK_PRESLIDING_DEG))
            drag[i] = p.sheath_drag_N / n
            drag[i, n] = 1000.0 * p.link_drag_Nm / r_t
            self._mu0[i], self._b[i] = p.sheath_friction, p.ageing_b
            self._dc[i], self._cutoff[i] = p.ageing_dc_mm, p.ageing_cutoff_s
            self._link[i] = p.link_friction
        self._set_wrap(sheath_curvature_deg)
        can_slide = np.ones(shape_n, dtype=bool)
        buckled = BUCKLED_SHARE * k
        buckled[:, [0, m]] = 0.0  # the slack rope in the handle pushes nothing
        self._const = ChainConstants(k, buckled, slack, ground, contact, drag, can_slide)
        self._radius_mm = np.array([p.pulley_radius_mm for p in self.knobs])
        self._offset_mm = np.array([p.tendon_offset_mm for p in self.knobs])
        self._handle_Nm = np.array([p.handle_friction_Nm for p in self.knobs])
        self._handle_speed = np.array([p.handle_speed_deg_s for p in self.knobs])
        self.last_iterations = 0
        self.reset()

    def _set_wrap(self, sheath_curvature_deg: float) -> None:
        """Each contact's wrap (rad) from the shaft's profile, the negative tendon's mirrored
        (its first contact from the tip is the distal one)."""
        n = NODES
        for i, p in enumerate(self.knobs):
            wrap = wrap_profile_rad(p.sheath_wrap_deg, n, p.curve_position, p.curve_share,
                                    sheath_curvature_deg)
            self._wrap[i, :n] = wrap
            self._wrap[i, n + 1:] = wrap[::-1]
        self.sheath_curvature_deg = sheath_curvature_deg

    def reshape(self, **changes: Any) -> None:
        """Change the catheter mid-run, the tendons staying where they are:
        ``sheath_curvature_deg`` (the shaft's extra bend, deg) and ``slack_delta_mm``
        (per knob ``(pos, neg)`` added to each tendon's slack, e.g. a stretched rope)."""
        unknown = sorted(set(changes) - {"sheath_curvature_deg", "slack_delta_mm"})
        if unknown:
            raise PlantLoadError(f"ratestate cannot reshape {', '.join(unknown)}; it takes "
                                 f"sheath_curvature_deg and slack_delta_mm")
        if "sheath_curvature_deg" in changes:
            bend = float(changes["sheath_curvature_deg"])
            if not (math.isfinite(bend) and bend >= 0.0):
                raise PlantLoadError(f"sheath_curvature_deg must be >= 0, got {bend!r}")
            self._set_wrap(bend)
        if "slack_delta_mm" in changes:
            delta = np.asarray(changes["slack_delta_mm"], dtype=float)
            if delta.shape != (2, 2) or not np.all(np.isfinite(delta)):
                raise PlantLoadError(f"slack_delta_mm must be ((pos, neg), (pos, neg)) in mm, "
                                     f"got {changes['slack_delta_mm']!r}")
            slack = self._const.slack_mm.copy()
            slack[:, 0] += delta[:, 0]
            slack[:, -1] += delta[:, 1]
            if np.any(slack < 0.0):
                raise PlantLoadError("slack_delta_mm would make a tendon's slack negative")
            self._const = dataclasses.replace(self._const, slack_mm=slack)

    def reset(self) -> None:
        """Straight, tension-free tendons; every contact freshly aged by one cut-off time."""
        m = 2 * NODES + 1
        self._state = ChainState(np.zeros((2, m)), np.zeros((2, m)),
                                 np.zeros((2, m + 1), dtype=bool), np.zeros((2, m)))
        self._age_s = self._cutoff.copy()
        self._knob_deg = np.zeros(2)
        self._tip_deg = np.zeros(2)
        self._handle_out = np.zeros(2)

    def step(self, dt_s: float, knob_deg: Any) -> PlantStep:
        q0, q1 = step_inputs(dt_s, knob_deg)
        q = np.array([q0, q1])
        n = NODES
        bend_rad = math.hypot(*np.radians(self._tip_deg))
        mu = aged_friction(self._mu0, self._b, self._age_s, self._cutoff)
        coupling = 0.5 * mu * self._wrap
        coupling[:, [n - 1, n + 1]] += (0.5 * bend_rad) * self._bend_mu[:, None]
        coupling[:, n] = self._link
        end_mm = -self._radius_mm * np.radians(q)
        old = self._state
        state, tension, _, self.last_iterations = solve(old, self._const, end_mm, coupling)
        self._age_s = age_after(self._age_s, state.anchor_mm - old.anchor_mm, dt_s, self._dc)
        self._state = state
        self._tip_deg = np.degrees(-state.d_mm[:, n] / self._offset_mm)
        if dt_s > 0.0:
            speed = (q - self._knob_deg) / dt_s
            self._handle_out = self._handle_Nm * np.tanh(speed / self._handle_speed)
        self._knob_deg = q
        tendon_Nm = 1e-3 * self._radius_mm * (tension[:, 0] - tension[:, -1])
        return PlantStep(self._tip_deg.copy(), tendon_Nm + self._handle_out)

    def tensions_N(self) -> FloatArray:
        """Element tensions of both loops (diagnostics and tests), shape (2, 2 NODES + 2)."""
        s = self._state
        ends = -self._radius_mm * np.radians(self._knob_deg)
        stretch = np.diff(np.concatenate([ends[:, None], s.d_mm, ends[:, None]], axis=1),
                          axis=1) - self._const.slack_mm
        return np.where(stretch > 0.0, self._const.k_N_per_mm, self._const.compressed_N_per_mm
                        ) * stretch


def make_ratestate_plant(knobs: Sequence[Mapping[str, Any] | RateStateKnobParams] | None = None,
                         sheath_curvature_deg: float = 0.0) -> RateStatePlant:
    """The ratestate plant; ``knobs`` overrides per knob (dicts of
    :class:`RateStateKnobParams` fields, or the dataclasses); ``sheath_curvature_deg`` bends
    the whole shaft mid-way (a curved path in the patient)."""
    return RateStatePlant(knob_params(knobs), sheath_curvature_deg)
