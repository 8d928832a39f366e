"""One quasi-static step of both knobs' tendon loops, solved together.

Each knob is one chain along the tendon loop: the drum, the positive tendon's contacts, the
tip, the negative tendon's contacts (distal first), the drum again. ``d`` is each node's
displacement along the loop (from the positive drum towards the negative one, mm); both drum
ends sit at ``-r q``. Element ``j`` joins nodes ``j-1`` and ``j``: tension
``T = EA/L (d_j - d_(j-1) - g_j)`` when stretched; compressed, a rope in the handle carries
nothing (``g``: the slack there), one in a lumen buckles into the lumen's clearance and pushes
back with a small share of its stiffness (``BUCKLED_SHARE``).
Node ``i`` balances ``T_(i+1) - T_i = kg_i d_i + f_i``: ``kg`` is the tip's bending spring,
``f`` a contact force, elastic ``kc (d - z)`` about its anchor ``z`` while it sticks, and
``s (c (T⁺_i + T⁺_(i+1)) + p)`` while it slides (normal force from the local tension and wrap;
a buckled rope's small push presses nothing: ``T⁺ = max(T, 0)``; plus preload). The active
sets (taut elements, sliding contacts and their direction) are found by a semi-smooth Newton
iteration started from the last step's, switching one kind at a time; each iteration is one
LAPACK tridiagonal solve (``dgtsv``) of both knobs' chains stacked.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.linalg.lapack import dgtsv

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

MAX_ITERATIONS = 8
TIE_N = 1e-9
TIE_MM = 1e-12
"""A contact at its bound, or an element at zero stretch, keeps its state within these (a tie
in floating point would otherwise switch it back and forth)."""
BUCKLED_SHARE = 0.02
"""Axial stiffness of a rope buckled into its lumen's clearance, as a share of its tensile
stiffness (helical buckling in a tube: the lumen wall holds the rope, weakly)."""
REGULARISE_N_PER_MM = 1e-6
"""A vanishing spring to the last position: keeps a sliding node between two slack elements
(no stiffness at all) solvable."""


@dataclass
class ChainState:
    """The loops' state, shape (knobs, nodes) or (knobs, elements)."""

    d_mm: FloatArray
    anchor_mm: FloatArray
    taut: BoolArray
    direction: FloatArray
    """+1 / -1 where a contact slides (the sign of its force), 0 where it sticks."""


@dataclass(frozen=True)
class ChainConstants:
    """What does not change within a step (shape (knobs, elements) or (knobs, nodes))."""

    k_N_per_mm: FloatArray
    compressed_N_per_mm: FloatArray
    slack_mm: FloatArray
    ground_N_per_mm: FloatArray
    contact_N_per_mm: FloatArray
    drag_N: FloatArray
    can_slide: BoolArray


def solve(state: ChainState, const: ChainConstants, end_mm: FloatArray, coupling: FloatArray
               ) -> tuple[ChainState, FloatArray, FloatArray, int]:
    """The loops' equilibrium with both drum ends at ``end_mm`` (per knob) and friction
    coefficients ``coupling`` (``c`` above, per node). Returns the new state, the element
    tensions (N), the contact forces (N) and the iterations used.

    Both knobs' chains are solved as one tridiagonal system (no entry joins them)."""
    k, kb, g = const.k_N_per_mm, const.compressed_N_per_mm, const.slack_mm
    kc, p = const.contact_N_per_mm, const.drag_N
    knobs, m = state.d_mm.shape
    taut, direction = state.taut, state.direction
    kcz = kc * state.anchor_mm
    fixed = const.ground_N_per_mm + REGULARISE_N_PER_MM
    eps_d = REGULARISE_N_PER_MM * state.d_mm
    joints = np.arange(1, knobs) * m - 1
    line = np.empty((knobs, m + 2))
    line[:, 0] = end_mm
    line[:, -1] = end_mm
    iterations = 0
    while True:
        iterations += 1
        ek = np.where(taut, k, kb)
        left, right = ek[:, :-1], ek[:, 1:]
        sig = direction * coupling
        stick = direction == 0.0
        upper = right * (1.0 - sig * taut[:, 1:])  # only a pulled rope presses on its lumen
        lower = left * (1.0 + sig * taut[:, :-1])
        rhs = (upper * g[:, 1:] - lower * g[:, :-1] - kcz * stick + direction * p - eps_d)
        rhs[:, 0] -= lower[:, 0] * end_mm
        rhs[:, -1] -= upper[:, -1] * end_mm
        diag = -(lower + upper) - kc * stick - fixed
        sub = lower.ravel()[1:]
        sup = upper.ravel()[:-1]
        sub[joints] = 0.0
        sup[joints] = 0.0
        d = dgtsv(sub, diag.ravel(), sup, rhs.ravel())[3].reshape(knobs, m)
        line[:, 1:-1] = d
        stretch = line[:, 1:] - line[:, :-1] - g
        new_taut = np.where(taut, stretch > -TIE_MM, stretch > TIE_MM)
        tension = np.where(new_taut, k, kb) * stretch
        pressing = np.maximum(tension, 0.0)
        bound = coupling * (pressing[:, :-1] + pressing[:, 1:]) + p
        trial = kc * d - kcz
        sliding = direction != 0.0
        keeps = sliding & (direction * trial >= bound - TIE_N)
        starts = ~sliding & (np.abs(trial) > bound + TIE_N)
        new_direction = np.where(keeps, direction, np.sign(trial) * (const.can_slide & starts))
        contacts_same = bool((new_direction == direction).all())
        elements_same = bool((new_taut == taut).all())
        if (contacts_same and elements_same) or iterations >= MAX_ITERATIONS:
            taut, direction = new_taut, new_direction
            break
        # One kind of switch at a time: switching contacts and elements together can cycle
        # (a dragged slack rope: taut and sliding one way <-> buckled and sliding the other).
        if contacts_same:
            taut = new_taut
        else:
            direction = new_direction
    # Where the sets did not settle (rare: a slack, buckled rope dragged through its lumen),
    # the last iterate's contact forces are projected onto their friction bounds.
    force = np.where(direction != 0.0, direction * bound, np.clip(trial, -bound, bound))
    anchor = np.where(direction != 0.0, d - force / kc, state.anchor_mm)
    return ChainState(d, anchor, taut, direction), tension, force, iterations
