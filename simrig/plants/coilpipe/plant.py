"""The coil-pipe plant: both knobs' tendon pairs, the shared shaft and the tips, solved together.

Coordinates (mm, positive = drawn towards the handle), per knob: the drum ``s`` (drum angle times
radius), the ``n`` sheath nodes of tendon a (pulled by positive knob angles) and of tendon b, and
the tip draw ``w`` (tip angle times tendon offset); last, the shaft's axial compression ``c``.
Elements between them: the handle gear (drive shaft to drum, with a gap), the cable segments
(tension only, slack and toe on the first), the tip's bending spring with a relaxing (Maxwell)
branch, and the shaft's axial spring loaded by every tendon's distal tension: the shaft shortens
under load, so both pairs lose draw (lost motion that grows with load, and a knob-to-knob
coupling). Every sheath node and the drum carry LuGre friction; a node's normal force grows with
the local tension times the local wrap (the lumen's helix, a curved sheath, and in the bending
section the tip's own bend). Quasi-static (no inertia: the cable and tip are light against the
drive), implicit in every state, Newton on the force balance each step.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantStep, step_inputs
from simrig.plants.coilpipe.laws import cable, lugre, stribeck
from simrig.plants.coilpipe.params import CoilPipeKnobParams, CoilPipePlantParams

Array = NDArray[np.float64]
_GEAR_TOE_MM = 0.01
"""Contact toe of the gear flank (surface roughness); keeps Newton's slope continuous."""
_SEGMENT_TOE_MM = 0.05
"""Straightening of a cable segment inside the lumen before it carries its stiffness."""
_TOL_MM = 2e-5
"""Newton stops below this correction (1e-5 mm is 0.0003 deg of tip at 4.5 mm)."""
_MAX_NEWTON = 12
_MAX_SPLITS = 6


def _per_knob(knobs: tuple[CoilPipeKnobParams, CoilPipeKnobParams], name: str) -> Array:
    return np.array([getattr(k, name) for k in knobs], dtype=float)


class CoilPipePlant:
    """Two knobs, four tendons in a compressible coil-pipe shaft; see the module docstring."""

    def __init__(self, knobs: tuple[CoilPipeKnobParams, CoilPipeKnobParams],
                 shared: CoilPipePlantParams) -> None:
        self.knobs = knobs
        self.shared = shared
        n = shared.sections
        self._n = n
        blk = 2 * n + 2  # coordinates per knob: drum, n nodes of a, n of b, tip
        m = 2 * blk + 1
        self._m = m
        eblk = 2 * n + 4  # elements per knob: gear, n+1 per tendon, tip
        n_el = 2 * eblk + 1
        a = np.zeros((n_el, m))
        c_idx = m - 1
        left = np.full(m, n_el - 1)  # elements either side of each coordinate (friction load)
        right = np.full(m, n_el - 1)
        first, section = [], np.full(m, -1)
        for k in range(2):
            b0, r0 = k * blk, k * eblk
            s, w = b0, b0 + blk - 1
            a[r0, s] = -1.0  # gear: e = r q - s
            for side, sign in ((0, 1.0), (1, -1.0)):
                nodes = [b0 + 1 + side * n + i for i in range(n)]
                rows = [r0 + 1 + side * (n + 1) + i for i in range(n + 1)]
                a[rows[0], s] = sign
                for i, node in enumerate(nodes):
                    a[rows[i], node] = -1.0
                    a[rows[i + 1], node] = 1.0
                    left[node], right[node], section[node] = rows[i], rows[i + 1], i
                a[rows[n], w] = -sign
                a[rows[n], c_idx] = -1.0
                first.append(rows[0])
            a[r0 + eblk - 1, w] = 1.0
        a[n_el - 1, c_idx] = 1.0
        self._A = a
        self._AT = a.T.copy()
        self._AL = a[left]
        self._AR = a[right]
        self._left, self._right = left, right
        self._gear = np.array([0, eblk])
        self._tip = np.array([eblk - 1, 2 * eblk - 1])
        self._first = np.array(first)  # tendon a, b of knob 0, then of knob 1
        self._drum = np.array([0, blk])
        self._w = np.array([blk - 1, 2 * blk - 1])
        self._section = section
        self._diag = np.arange(m) * (m + 1)
        self._blk_sizes = (blk, eblk)
        self._slack_delta_mm = np.zeros(4)
        self._set_constants(blk, eblk)
        self.reset()

    def reshape(self, **changes: Any) -> None:
        """The catheter changes shape mid-run (``simrig.scenario``): ``slack_delta_mm`` (per
        knob, (positive, negative) tendon: more slack, e.g. a tendon settling) and
        ``sheath_curvature_deg`` (the sheath laid in a curve). The state stays."""
        unknown = sorted(set(changes) - {"slack_delta_mm", "sheath_curvature_deg"})
        if unknown:
            raise ValueError(f"coilpipe plant cannot change {', '.join(unknown)}")
        if "slack_delta_mm" in changes:
            delta = np.asarray(changes["slack_delta_mm"], dtype=float).reshape(4)
            if not np.all(np.isfinite(delta)):
                raise ValueError("coilpipe slack_delta_mm must be finite")
            self._slack_delta_mm = self._slack_delta_mm + delta
        if "sheath_curvature_deg" in changes:
            curve = float(changes["sheath_curvature_deg"])
            if not (math.isfinite(curve) and curve >= 0.0):
                raise ValueError("coilpipe sheath_curvature_deg must be finite and >= 0")
            self.shared = dataclasses.replace(self.shared, sheath_curvature_deg=curve)
        self._set_constants(*self._blk_sizes)

    def _set_constants(self, blk: int, eblk: int) -> None:
        kn, sh, n = self.knobs, self.shared, self._n
        r = _per_knob(kn, "pulley_radius_mm")
        self._r_mm = r
        self._d_mm = _per_knob(kn, "tendon_offset_mm")
        ea = _per_knob(kn, "tendon_stiffness_N")
        seg = _per_knob(kn, "sheath_length_m") * 1e3 / n
        lf_mm = _per_knob(kn, "free_length_m") * 1e3
        n_el = self._A.shape[0]
        k_pos = np.zeros(n_el)
        k_neg = np.zeros(n_el)
        toe = np.full(n_el, _SEGMENT_TOE_MM)
        gap = np.zeros(n_el)
        k_lin = np.zeros(n_el)
        for k in range(2):
            r0 = k * eblk
            k_gear = kn[k].gear_stiffness_Nm_per_deg * (180.0 / math.pi) / (r[k] ** 2 * 1e-3)
            k_pos[r0] = k_neg[r0] = k_gear
            toe[r0] = _GEAR_TOE_MM
            gap[r0] = 0.5 * math.radians(kn[k].gear_backlash_deg) * r[k]
            for side in range(2):
                row0 = r0 + 1 + side * (n + 1)
                k_pos[row0] = ea[k] / (lf_mm[k] + 0.5 * seg[k])
                k_pos[row0 + 1:row0 + n] = ea[k] / seg[k]
                k_pos[row0 + n] = ea[k] / (0.5 * seg[k])
                toe[row0] = kn[k].toe_mm
        k_lin[n_el - 1] = sh.shaft_stiffness_N_per_mm
        self._kk = np.concatenate((k_pos, k_neg))
        self._toe2 = np.concatenate((toe, toe))
        self._gap = gap
        self._k_lin0 = k_lin
        self._slack = np.array([kn[0].slack_pos_mm, kn[0].slack_neg_mm,
                                kn[1].slack_pos_mm, kn[1].slack_neg_mm]) + self._slack_delta_mm
        d = self._d_mm
        self._k_tip = _per_knob(kn, "bend_stiffness_Nm_per_rad") / (d * d * 1e-3)
        self._k_creep = _per_knob(kn, "bend_creep_stiffness_Nm_per_rad") / (d * d * 1e-3)
        self._creep_s = _per_knob(kn, "bend_creep_time_s")
        # friction on every coordinate (zero where there is none: tips, shaft)
        knob = np.repeat([0, 1, 1], [blk, blk, 1])
        sheath = self._section >= 0
        curve_rad = math.radians(sh.sheath_curvature_deg)
        lo, hi = n // 4, n - n // 4
        middle = sheath & (self._section >= lo) & (self._section < hi)
        wrap = np.where(sheath, np.radians(_per_knob(kn, "sheath_wrap_deg"))[knob] / n, 0.0)
        wrap += np.where(middle, curve_rad / max(hi - lo, 1), 0.0)
        self._mu = np.where(sheath, _per_knob(kn, "sheath_friction")[knob], 0.0)
        self._wrap0 = wrap
        self._bend_node = self._section == n - 1
        self._knob = knob
        drag = np.where(sheath, _per_knob(kn, "sheath_drag_N")[knob] / n, 0.0)
        drag[self._drum] = _per_knob(kn, "handle_friction_Nm") / (r * 1e-3)
        self._drag = drag
        self._visc = np.where(sheath, _per_knob(kn, "viscous_N_s_per_mm")[knob] / n, 0.0)
        pre = np.where(sheath, _per_knob(kn, "presliding_mm")[knob], 1.0)
        pre[self._drum] = np.radians(_per_knob(kn, "handle_presliding_deg")) * r
        self._pre = pre
        self._ratio = _per_knob(kn, "stribeck_ratio")[knob]
        self._vs = _per_knob(kn, "stribeck_speed_mm_s")[knob]
        self._curve_slack_mm = sh.lumen_clearance_mm * curve_rad

    def reset(self) -> None:
        """Straight and unloaded: every coordinate, bristle and creep state at zero."""
        self._x = np.zeros(self._m)
        self._v = np.zeros(self._m)
        self._gear_N = np.zeros(2)
        self._z = np.zeros(self._m)
        self._w_creep = np.zeros(2)
        self._tip_rad = np.zeros(2)
        self._drive_mm = np.zeros(2)
        self._last = PlantStep(np.zeros(2), np.zeros(2))

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        """Advance by ``dt_s`` with the drive shafts at ``knob_deg`` (knob degrees)."""
        q0, q1 = step_inputs(dt_s, knob_deg)
        if dt_s == 0.0:
            return self._last
        drive_mm = np.radians([q0, q1]) * self._r_mm
        self._advance(dt_s, drive_mm, _MAX_SPLITS)
        torque = self._gear_N * self._r_mm * 1e-3
        self._last = PlantStep(np.degrees(self._tip_rad), torque)
        return self._last

    def _advance(self, dt_s: float, drive_mm: Array, splits: int) -> None:
        """One implicit step to ``drive_mm``; halved (up to ``splits`` times) where Newton does
        not settle (a sudden stick-slip event inside a long step)."""
        sh = self.shared
        # a shorter path is more slack: the sheath laid in a curve, the other plane bent
        lost = self._curve_slack_mm + sh.coupling_mm_per_rad2 * np.square(self._tip_rad[::-1])
        offset = np.zeros(self._A.shape[0])
        offset[self._gear] = -drive_mm
        offset[self._first] = self._slack + np.repeat(lost, 2)
        bend = np.where(self._bend_node, sh.bend_section_wrap_ratio
                        * np.abs(self._tip_rad)[np.minimum(self._knob, 1)], 0.0)
        mu_wrap = self._mu * (self._wrap0 + bend)
        alpha = dt_s / self._creep_s
        k_creep = self._k_creep / (1.0 + alpha)
        k_lin = self._k_lin0.copy()
        k_lin[self._tip] = self._k_tip + k_creep
        bias = np.zeros_like(k_lin)
        bias[self._tip] = k_creep * self._w_creep
        level = stribeck(self._v, self._ratio, self._vs)
        x_old = self._x
        x = x_old + self._v * dt_s  # first guess: the last step's speed again
        x[self._drum] = x_old[self._drum] + drive_mm - self._drive_mm
        solved = self._newton(x, x_old, offset, k_lin, bias, mu_wrap, level, dt_s)
        if solved is None:
            if splits == 0:
                raise FloatingPointError("coilpipe plant: the step did not converge")
            middle = 0.5 * (self._drive_mm + drive_mm)
            self._advance(0.5 * dt_s, middle, splits - 1)
            self._advance(0.5 * dt_s, drive_mm, splits - 1)
            return
        x, f = solved
        self._z = lugre(self._z, x - x_old, self._pre, level)[0]
        w = x[self._w]
        self._w_creep = (self._w_creep + alpha * w) / (1.0 + alpha)
        self._v = (x - x_old) / dt_s
        self._x = x
        self._drive_mm = drive_mm
        self._tip_rad = w / self._d_mm
        self._gear_N = f[self._gear]

    def _forces(self, x: Array, offset: Array, k_lin: Array, bias: Array
                ) -> tuple[Array, Array]:
        """Every element's force (N) and slope (N/mm) at ``x``."""
        e = self._A @ x - offset
        both = np.concatenate((e - self._gap, -e - self._gap))
        t, dt = cable(both, self._kk, self._toe2)
        n_el = e.size
        f = t[:n_el] - t[n_el:] + k_lin * e - bias
        df = dt[:n_el] + dt[n_el:] + k_lin
        return f, df

    def _newton(self, x: Array, x_old: Array, offset: Array, k_lin: Array, bias: Array,
                mu_wrap: Array, level: Array, dt_s: float) -> tuple[Array, Array] | None:
        """Solve the force balance at the step's end (friction implicit in its bristles);
        None if Newton does not settle."""
        A, AT = self._A, self._AT
        for _ in range(_MAX_NEWTON):
            f, df = self._forces(x, offset, k_lin, bias)
            d = x - x_old
            z1, dz = lugre(self._z, d, self._pre, level)
            # LuGre: the normal force grows with the local tension times the local wrap
            load = 0.5 * mu_wrap * (f[self._left] + f[self._right]) + self._drag
            residual = AT @ f + load * z1 + self._visc * (d / dt_s)
            jac = (AT * df) @ A
            jac += (0.5 * mu_wrap * z1)[:, None] * (df[self._left, None] * self._AL
                                                    + df[self._right, None] * self._AR)
            jac.flat[self._diag] += load * dz + self._visc / dt_s
            delta = np.linalg.solve(jac, residual)
            x = x - delta
            if float(np.max(np.abs(delta))) < _TOL_MM:
                return x, self._forces(x, offset, k_lin, bias)[0]
        return None
