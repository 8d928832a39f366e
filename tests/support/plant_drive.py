"""Driving a family plant alone, one knob along a path, as the plants' own tests do."""

from __future__ import annotations

from typing import Any

import numpy as np

STEP_S = 0.004
"""The rig's period: the plants are stepped at it in their tests."""


def drive_knob(plant: Any, knob: int, path_deg: np.ndarray, other_deg: float = 0.0
               ) -> tuple[np.ndarray, np.ndarray]:
    """Tip (deg) and knob torque (N m) of ``knob`` along ``path_deg``, the other knob held."""
    tips, torques = np.empty_like(path_deg), np.empty_like(path_deg)
    cmd = np.zeros(2)
    cmd[1 - knob] = other_deg
    for i, q in enumerate(path_deg):
        cmd[knob] = q
        step = plant.step(STEP_S, cmd)
        tips[i], torques[i] = step.tip_deg[knob], step.knob_torque_Nm[knob]
    return tips, torques


def ramp_deg(a: float, b: float, speed_deg_s: float = 20.0) -> np.ndarray:
    """Knob angles from ``a`` to ``b`` at ``speed_deg_s``, one per rig period."""
    n = max(2, int(abs(b - a) / (speed_deg_s * STEP_S)))
    return np.linspace(a, b, n)
