"""The segments plant: each tendon a chain of elastic elements along the sheath, every element
with its own elasto-plastic friction contact, and a bending tip with its own hysteresis.

Per knob, two antagonistic tendons. Tendon ``s`` (+1 drawn in by positive knob rotation, -1 paid
out) is pulled at the pulley by ``p = s r phi - slack`` (m). Between pulley and sheath entry a
free segment with a recruitment toe (``laws.recruit``); then ``N`` nodes along the sheath joined
by segments of stiffness ``N EA / L`` that carry no compression; the last segment ends on the tip
at ``s r_b theta``. Node ``j`` (displacement ``u_j`` towards the handle) feels the segments on
either side and a friction force ``Fc_j z_j / z_max`` whose contact state ``z_j`` follows the
node's travel (elasto-plastic presliding); its capacity grows with the local tension as on a
capstan, ``Fc_j = mu dpsi (T_j + T_j+1) / 2 + h / N``. The tip balances
``r_b (T_N+ - T_N-) = K0 theta (1 + c theta^2) + M_h h`` with ``h`` a Bouc-Wen state.

Each step is an implicit (backward Euler, linearised) step of the overdamped chain: a small lumen
drag keeps it well posed while a tendon is slack, and the linearisation's residual is carried to
the next step. A contact that turns round within the step has its tangent changed and the step
is solved again. Steps are cut into pieces of at most 0.4 presliding displacements of pulley
travel, so the loops do not depend on the tick (100 us to 4 ms) or on the knob speed.
"""

from __future__ import annotations

import math
from typing import cast

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantStep, step_inputs
from simrig.plants.segments.laws import (
    bouc_wen_slope,
    bouc_wen_update,
    presliding_slope,
    presliding_update,
    recruit,
)
from simrig.plants.segments.params import SegmentsKnobParams, SegmentsPlantParams

Array = NDArray[np.float64]
_SIGN = np.array([1.0, -1.0])  # tendon "+" then "-"
_TIP_DAMPING_Nm_s_per_rad = 5e-6  # the tip in fluid: relaxes in ~1 ms when both tendons are slack
_MAX_PIECES = 400
_SETTLED_M = 1e-10


def _per_knob(knobs: tuple[SegmentsKnobParams, SegmentsKnobParams], name: str) -> Array:
    return np.array([float(getattr(k, name)) for k in knobs])


class SegmentsPlant:
    """Two knobs, four tendons of ``n_elements`` elements each, two bending planes."""

    def __init__(self, knobs: tuple[SegmentsKnobParams, SegmentsKnobParams],
                 settings: SegmentsPlantParams) -> None:
        self.knobs = knobs
        self.settings = settings
        n = settings.n_elements
        self._n = n
        g = lambda name: _per_knob(knobs, name)  # noqa: E731
        self._r_m = g("pulley_radius_mm") * 1e-3
        self._rb_m = g("tendon_offset_mm") * 1e-3
        self._slack_m = np.stack([g("slack_pos_mm"), g("slack_neg_mm")], axis=1) * 1e-3
        ea = g("tendon_stiffness_N")
        stiffness = np.empty((2, n + 1))
        stiffness[:, 0] = ea / g("free_length_m")
        stiffness[:, 1:] = (ea * n / g("sheath_length_m"))[:, None]
        self._k = stiffness[:, None, :]  # (knob, 1, segment)
        toe = np.empty((2, n + 1))
        toe[:, 0] = g("toe_mm") * 1e-3
        toe[:, 1:] = 1e-6  # inside the sheath: engages over 1 um, smooth for the solver
        self._toe = toe[:, None, :]
        self._slack_delta_m = np.zeros((2, 2))
        self._set_curvature(settings.sheath_curvature_deg)
        self._drag_N = (g("sheath_drag_N") / n)[:, None, None]
        self._z_max = (g("presliding_mm") * 1e-3)[:, None, None]
        self._stick = g("stick_fraction")[:, None, None]
        self._k_bend = g("bend_stiffness_Nm_per_rad")
        self._c_bend = g("bend_stiffening_per_rad2")
        self._m_hyst = g("bend_hysteresis_Nm")
        self._yield = np.radians(g("bend_yield_deg"))
        self._handle_Nm = g("handle_friction_Nm")
        self._handle_z_max = np.radians(g("handle_presliding_deg"))
        self._handle_stick = np.zeros(2)  # the knob's bearings: no true stick, Dahl-like
        self._b_node = settings.viscous_N_s_per_m / n
        self._shift = settings.coupling * math.sin(math.radians(settings.coupling_lumen_angle_deg))
        self._compress = settings.coupling * settings.coupling_compression_mm_per_N * 1e-3
        self._piece_m = 0.4 * float(np.min(self._z_max))
        m = 2 * n + 1
        self._m = m
        nodes = np.arange(2 * n)
        self._diag = (nodes, nodes)
        left = np.concatenate([np.arange(n - 1), n + np.arange(n - 1)])
        self._off = (left, left + 1)
        self._last = np.array([n - 1, 2 * n - 1])
        self._a = np.zeros((2, m, m))  # only the chain's entries are ever written
        self._rhs = np.zeros((2, m))
        self._stretch = np.empty((2, 2, n + 1))
        self.reset()

    def reset(self) -> None:
        """Straight and unloaded: every tendon at rest, every contact and the tip relaxed."""
        n = self._n
        self._u = np.zeros((2, 2, n))
        self._z = np.zeros((2, 2, n))
        self._dir = np.zeros((2, 2, n))
        self._theta = np.zeros(2)
        self._h = np.zeros(2)
        self._dir_theta = np.zeros(2)
        self._z_handle = np.zeros(2)
        self._knob_rad = np.zeros(2)
        self._tension0 = np.zeros((2, 2))
        self._settled = True

    def reshape(self, sheath_curvature_deg: float | None = None,
                slack_delta_mm: tuple[tuple[float, float], tuple[float, float]] | None = None
                ) -> None:
        """The catheter changes shape mid-run (``simrig.scenario.ShapeChangePlant``): the sheath
        laid in a new curve, or every tendon's slack changed by ((+, -) knob 1, (+, -) knob 2)
        mm from the unit's own. The tendons' and contacts' states are kept."""
        if sheath_curvature_deg is not None:
            if not (math.isfinite(sheath_curvature_deg) and sheath_curvature_deg >= 0.0):
                raise ValueError(f"sheath_curvature_deg must be >= 0, got "
                                 f"{sheath_curvature_deg!r}")
            self._set_curvature(float(sheath_curvature_deg))
        if slack_delta_mm is not None:
            delta = np.asarray(slack_delta_mm, dtype=float)
            if delta.shape != (2, 2) or not np.all(np.isfinite(delta)):
                raise ValueError(f"slack_delta_mm must be ((+, -), (+, -)) in mm, got "
                                 f"{slack_delta_mm!r}")
            self._slack_delta_m = delta * 1e-3
        self._settled = False

    def _set_curvature(self, curvature_deg: float) -> None:
        """A curved sheath adds its angle to every element's wrap and lets the tendon take the
        inner side of its lumen (a shorter path: more slack)."""
        curvature_rad = math.radians(curvature_deg)
        wrap_rad = np.radians(_per_knob(self.knobs, "sheath_wrap_deg")) + curvature_rad
        friction = _per_knob(self.knobs, "sheath_friction")
        self._mu_dpsi = (friction * wrap_rad / self._n)[:, None, None]
        self._curvature_slack_m = self.settings.lumen_clearance_mm * 1e-3 * curvature_rad

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        """Advance by ``dt_s`` with the knobs ending at ``knob_deg``."""
        q0, q1 = step_inputs(dt_s, knob_deg)
        target = np.radians([q0, q1])
        move = target - self._knob_rad
        if not (self._settled and not move.any()):
            travel_m = float(np.max(np.abs(move) * self._r_m))
            pieces = min(_MAX_PIECES, max(1, math.ceil(travel_m / self._piece_m)))
            start = self._knob_rad
            dt_piece = max(dt_s / pieces, 1e-6)
            moved = 0.0
            for i in range(1, pieces + 1):
                knob = start + move * (i / pieces)
                moved = self._piece(dt_piece, knob)
            self._z_handle = presliding_update(self._z_handle, move, self._handle_z_max,
                                                    self._handle_stick)
            self._knob_rad = target
            stretch0 = self._draw_in(target) - self._u[..., 0]
            self._tension0 = recruit(stretch0, self._toe[..., 0], self._k[..., 0])[0]
            self._settled = moved < _SETTLED_M
        torque = (self._r_m * (self._tension0[:, 0] - self._tension0[:, 1])
                  + self._handle_Nm * self._z_handle / self._handle_z_max)
        return PlantStep(np.degrees(self._theta), torque)

    def _draw_in(self, knob_rad: Array) -> Array:
        """Pulley draw-in of each tendon minus its slack and the sheath's shortening (m)."""
        p = (_SIGN[None, :] * (self._r_m * knob_rad)[:, None] - self._slack_m
             - self._slack_delta_m - self._curvature_slack_m)
        if self._shift or self._compress:
            other_theta = self._theta[::-1]
            other_tension = self._tension0.sum(axis=1)[::-1]
            p -= _SIGN[None, :] * (self._rb_m * self._shift * other_theta)[:, None]
            p -= (self._compress * other_tension)[:, None]
        return p

    def _forces(self, p: Array) -> tuple[Array, Array, Array]:
        """Segment tensions and tangent stiffnesses, and each node's friction capacity."""
        u = self._u
        n = self._n
        stretch = self._stretch
        stretch[..., 0] = p - u[..., 0]
        stretch[..., 1:n] = u[..., :-1] - u[..., 1:]
        stretch[..., n] = u[..., -1] - _SIGN[None, :] * (self._rb_m * self._theta)[:, None]
        tension, tangent = recruit(stretch, self._toe, self._k)
        capacity = self._mu_dpsi * 0.5 * (tension[..., :-1] + tension[..., 1:]) + self._drag_N
        return tension, tangent, capacity

    def _piece(self, dt_s: float, knob_rad: Array) -> float:
        """One linearised implicit step to ``knob_rad``; returns the largest node travel (m)."""
        n, m = self._n, self._m
        tension, tangent, capacity = self._forces(self._draw_in(knob_rad))
        theta = self._theta
        r_nodes = tension[..., :-1] - tension[..., 1:] - capacity * self._z / self._z_max
        r_tip = (self._rb_m * (tension[:, 0, n] - tension[:, 1, n])
                 - self._k_bend * theta * (1.0 + self._c_bend * theta * theta)
                 - self._m_hyst * self._h)
        rhs = self._rhs
        rhs[:, :2 * n] = r_nodes.reshape(2, 2 * n)
        rhs[:, m - 1] = r_tip
        k_end = tangent[..., n]
        direction, dir_theta = self._dir, self._dir_theta
        for _ in range(3):
            a = self._a
            contact = capacity / self._z_max * presliding_slope(
                self._z, direction, self._z_max, self._stick)
            diag = tangent[..., :-1] + tangent[..., 1:] + contact + self._b_node / dt_s
            a[:, self._diag[0], self._diag[1]] = diag.reshape(2, 2 * n)
            off = -tangent[..., 1:n].reshape(2, 2 * (n - 1))
            a[:, self._off[0], self._off[1]] = off
            a[:, self._off[1], self._off[0]] = off
            cross = -_SIGN[None, :] * self._rb_m[:, None] * k_end
            a[:, self._last, m - 1] = cross
            a[:, m - 1, self._last] = cross
            bend = (self._k_bend * (1.0 + 3.0 * self._c_bend * theta * theta)
                    + self._m_hyst * bouc_wen_slope(self._h, dir_theta, self._yield))
            a[:, m - 1, m - 1] = (self._rb_m ** 2 * k_end.sum(axis=1) + bend
                                  + _TIP_DAMPING_Nm_s_per_rad / dt_s)
            dx = cast(Array, np.linalg.solve(a, rhs[..., None])[..., 0])
            du = dx[:, :2 * n].reshape(2, 2, n)
            dtheta = dx[:, m - 1]
            new_dir = np.where(np.abs(du) > 1e-12, np.sign(du), direction)
            new_dir_theta = np.where(np.abs(dtheta) > 1e-12, np.sign(dtheta), dir_theta)
            if np.array_equal(new_dir, direction) and np.array_equal(new_dir_theta, dir_theta):
                break
            direction, dir_theta = new_dir, new_dir_theta
        self._z = presliding_update(self._z, du, self._z_max, self._stick)
        self._u = self._u + du
        self._h = bouc_wen_update(self._h, dtheta, self._yield)
        self._theta = theta + dtheta
        self._dir, self._dir_theta = direction, dir_theta
        return float(max(np.max(np.abs(du)), float(np.max(np.abs(dtheta))) * 1e-3))
