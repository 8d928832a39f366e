"""A small stand-in catheter plant and data maker for the gap tests (not the project's plant).

Per knob: tendon slack (dead zone), sheath friction as a play operator (backlash), a linear
bending section, torque from tendon tension plus a friction term that flips with direction.
Optional effects, written for the tests only: ``coupling_deg`` (slack grows with the other knob's
bend) and ``lag_s`` (the measured current lags the true current).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantStep
from tsmd.recording import Recording


class StandInPlant:
    def __init__(self, slack_deg: float = 18.0, play_deg: float = 10.0, slope: float = 1.3,
                 stiffness_Nm_per_deg: float = 0.003, friction_Nm: float = 0.02,
                 coupling_deg: float = 0.0) -> None:
        self.slack_deg = slack_deg
        self.play_deg = play_deg
        self.slope = slope
        self.k = stiffness_Nm_per_deg
        self.friction_Nm = friction_Nm
        self.coupling_deg = coupling_deg
        self.reset()

    def reset(self) -> None:
        self._x = np.zeros(2)
        self._last = np.zeros(2)

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        knob = np.asarray(knob_deg, dtype=float)
        slack = self.slack_deg + self.coupling_deg * np.abs(knob[::-1]) / 90.0
        pull = np.sign(knob) * np.maximum(np.abs(knob) - slack, 0.0)
        self._x = np.clip(self._x, pull - self.play_deg, pull + self.play_deg)
        direction = np.sign(knob - self._last)
        self._last = knob.copy()
        tip = self.slope * self._x
        torque = self.k * self._x + self.friction_Nm * direction * (np.abs(pull) > 0)
        return PlantStep(tip, torque)


def make_stand_in(**params: float) -> StandInPlant:
    return StandInPlant(**params)


def trajectory(duration_s: float, rate_hz: float) -> tuple[NDArray[np.float64],
                                                            NDArray[np.float64]]:
    """Both knobs swept +-80 deg at incommensurate, slowly varying rates."""
    t = np.arange(0.0, duration_s, 1.0 / rate_hz)
    phase1 = 2 * np.pi * (0.05 * t + 0.02 * np.sin(2 * np.pi * t / 97.0) * 10)
    phase2 = 2 * np.pi * (0.031 * t)
    q = np.column_stack([80 * np.sin(phase1), 70 * np.sin(phase2 + 0.7)])
    return t, q


def make_recording(duration_s: float = 240.0, rate_hz: float = 50.0, seed: int = 0,
                   tip_noise_deg: float = 0.3, cur_noise_A: float = 0.005,
                   lag_s: float = 0.0, tip_drift_deg_s: float = 0.0,
                   **plant_params: float) -> Recording:
    """A 'real' recording from the stand-in plant, current = 2 A/Nm * torque + noise."""
    rng = np.random.default_rng(seed)
    t, q = trajectory(duration_s, rate_hz)
    plant = StandInPlant(**plant_params)
    tip = np.empty_like(q)
    torque = np.empty_like(q)
    dt = 1.0 / rate_hz
    for k in range(len(t)):
        out = plant.step(dt, q[k])
        tip[k], torque[k] = out.tip_deg, out.knob_torque_Nm
    cur = 2.0 * torque + 0.01
    if lag_s > 0:
        a = np.exp(-dt / lag_s)
        for k in range(1, len(t)):
            cur[k] = a * cur[k - 1] + (1 - a) * cur[k]
    tip = tip + tip_drift_deg_s * t[:, None]
    tip = tip + rng.normal(0, tip_noise_deg, tip.shape)
    cur = cur + rng.normal(0, cur_noise_A, cur.shape)
    cols = {"t": t, "q1": q[:, 0], "q2": q[:, 1], "cmd1": q[:, 0], "cmd2": q[:, 1],
            "pos1": q[:, 0], "pos2": q[:, 1], "cur1": cur[:, 0], "cur2": cur[:, 1],
            "tip1": tip[:, 0], "tip2": tip[:, 1]}
    cols = {k: v.copy() for k, v in cols.items()}
    return Recording(cols, {"source": "stand-in"})
