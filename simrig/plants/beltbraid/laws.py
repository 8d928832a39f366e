"""Constitutive laws of the beltbraid plant, each a small pure function or state machine.

* the braided lumen's friction on a rope is distributed microslip: the slip zone spreads from
  the loaded end along the whole lumen before the rope slides, so the mobilised fraction ``w`` of
  the capacity follows a Bouc-Wen law (order 2, beta = gamma) of the rope's slip with a slip
  length that grows with the tension (a tauter rope must stretch further along the lumen);
* the braided shaft shortens under the ropes' reaction as its wire crossings slip one by one: a
  Preisach set of relays (each crossing slips forward at one load and back at a lower one);
* the knob's belt creeps (Reynolds): the drum loses a share of the knob's travel proportional to
  the torque it carries, always toward unloading;
* the knob's preloaded antagonistic return springs.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

_W_MAX = 1.0 - 1e-12


def microslip(w: float, slip_mm: float, slip_len_mm: float) -> float:
    """Mobilised fraction after the rope slips ``slip_mm`` at the contact (Bouc-Wen, n = 2).

    Moving against the friction's present sense unloads it at the initial rate (1/slip length);
    moving with it loads along dw/ds = 1 - w^2 (the tanh), so it approaches +-1 and stays there
    while the rope slides.
    """
    if slip_mm == 0.0:
        return w
    s = slip_mm / slip_len_mm
    if s > 0.0:
        if w < 0.0:
            w += s
            if w <= 0.0:
                return w
            s, w = w, 0.0
        return math.tanh(math.atanh(min(w, _W_MAX)) + s)
    if w > 0.0:
        w += s
        if w >= 0.0:
            return w
        s, w = w, 0.0
    return math.tanh(math.atanh(max(w, -_W_MAX)) + s)


def microslip_rate(w: float, direction: float, slip_len_mm: float) -> float:
    """dw/ds of :func:`microslip` at ``w`` when the rope slips in ``direction`` (+1/-1)."""
    if direction * w > 0.0:
        return (1.0 - w * w) / slip_len_mm
    return 1.0 / slip_len_mm


class BraidRelays:
    """Wire crossings of the braided shaft as Preisach relays on the total rope load (N).

    A crossing ``i`` slips forward (adding its share of shortening) once the load reaches
    ``forward_N[i]`` and slips back only when the load has fallen to ``back_N[i]``; the hold
    widths differ crossing to crossing (their normal loads differ along the braid), so the
    set is not one play operator.
    """

    COUNT = 64

    def __init__(self, onset_N: float, span_N: float, hold_N: float, slip_mm: float) -> None:
        i = np.arange(self.COUNT, dtype=float)
        self.forward_N: NDArray[np.float64] = onset_N + span_N * (i + 0.5) / self.COUNT
        widths = hold_N * (0.4 + 1.2 * ((i * 7.0) % self.COUNT) / (self.COUNT - 1))
        self.back_N: NDArray[np.float64] = self.forward_N - widths
        self.share_mm = slip_mm / self.COUNT
        self.slipped: NDArray[np.bool_] = np.zeros(self.COUNT, dtype=bool)
        self.count = 0

    def reset(self) -> None:
        self.slipped[:] = False
        self.count = 0

    def update(self, load_N: float) -> float:
        """Shortening (mm) after the load moved to ``load_N``."""
        if load_N >= self.forward_N[0] or self.count:
            self.slipped = (self.slipped | (self.forward_N <= load_N)) & (self.back_N < load_N)
            self.count = int(np.count_nonzero(self.slipped))
        return self.count * self.share_mm


def return_spring_Nm(knob_rad: float, preload_Nm: float, rate_Nm_per_rad: float,
                     width_rad: float) -> float:
    """Torque of the knob's preloaded antagonistic springs (resisting motion off centre)."""
    return preload_Nm * math.tanh(knob_rad / width_rad) + rate_Nm_per_rad * knob_rad
