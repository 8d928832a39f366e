"""Support for the calibration tests (no tests here): a small runner over a plant.

``LockstepPlantRunner`` implements the ``TrajectoryRunner`` protocol without the CAN stack: a
first-order position servo per knob, the plant's knob torque turned into motor current through a
torque constant and gear ratio, Coulomb friction at the motor, sensor noise. It lets the
calibration tests run fast; the shipped path uses the daemon's runner (full CAN stack).

``SlackFrictionPlant`` is a minimal physical plant for when A's plant is not importable: two
antagonistic tendons with slack, an elastic bending section held by Coulomb friction (stick-slip,
quasi-static) and capstan friction in the sheath between the knob and the distal tendon.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from simrig.plant import PlantStep
from tsmd.recording import Recording


class SlackFrictionPlant:
    """Tendon slack (dead zone) + bending friction (backlash) + sheath capstan (current shape)."""

    def __init__(self, slack_deg: float = 18.0, friction_Nm: float = 0.02,
                 tendon_Nm_per_deg: float = 0.01, bending_Nm_per_deg: float = 0.0025,
                 slope: float = 1.3, capstan: float = 1.2, coupling: float = 0.1) -> None:
        self.slack_deg = slack_deg
        self.friction_Nm = friction_Nm
        self.k_t = tendon_Nm_per_deg
        self.k_b = bending_Nm_per_deg
        self.slope = slope
        self.capstan = capstan
        self.coupling = coupling
        self.reset()

    def reset(self) -> None:
        self.tip = np.zeros(2)
        self.last_knob = np.zeros(2)
        self.torque = np.zeros(2)

    def _drive(self, x: float, tip: float, slack: float) -> float:
        u = x - tip / self.slope
        return self.k_t * (max(0.0, u - slack) - max(0.0, -u - slack))

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        knob = np.asarray(knob_deg, dtype=float)
        for i in range(2):
            other = knob[1 - i]
            slack = self.slack_deg * (1.0 + self.coupling * (other / 90.0) ** 2)
            x = float(knob[i])
            tip = float(self.tip[i])
            net = self._drive(x, tip, slack) - self.k_b * tip
            if abs(net) > self.friction_Nm:
                target = self.friction_Nm if net > 0 else -self.friction_Nm
                lo, hi = (tip, tip + 400.0) if net > 0 else (tip - 400.0, tip)
                for _ in range(60):
                    mid = 0.5 * (lo + hi)
                    if self._drive(x, mid, slack) - self.k_b * mid > target:
                        lo = mid
                    else:
                        hi = mid
                tip = 0.5 * (lo + hi)
            self.tip[i] = tip
            distal = self._drive(x, tip, slack)
            velocity = x - self.last_knob[i]
            pulling = velocity * distal > 0
            factor = math.exp(self.capstan) if pulling else math.exp(-self.capstan)
            if abs(velocity) < 1e-12:
                factor = 1.0
            self.torque[i] = distal * factor
        self.last_knob = knob.copy()
        return PlantStep(self.tip.copy(), self.torque.copy())


class LockstepPlantRunner:
    """Runs a trajectory tick by tick on a plant; records like the daemon's recorder."""

    def __init__(self, plant: object, period_s: float = 0.004, seed: int = 0,
                 current_noise_A: float = 0.01, amps_per_Nm: float = 2.0,
                 motor_friction_A: float = 0.03, servo_bandwidth_hz: float = 20.0,
                 stall_after_s: float | None = None, spike_rate: float = 0.0) -> None:
        self.plant = plant
        self.period_s = period_s
        self.rng = np.random.default_rng(seed)
        self.noise = current_noise_A
        self.amps_per_Nm = amps_per_Nm
        self.motor_friction_A = motor_friction_A
        self.alpha = 1.0 - math.exp(-2 * math.pi * servo_bandwidth_hz * period_s)
        self.stall_after_s = stall_after_s
        self.spike_rate = spike_rate
        self.pos = np.zeros(2)
        self.time_s = 0.0
        self.runs = 0
        self.trajectories: list[NDArray[np.float64]] = []

    def run(self, t_s: NDArray[np.float64], q_deg: NDArray[np.float64], compensate: bool = False,
            cancel: threading.Event | None = None,
            progress: Callable[[float], None] | None = None) -> Recording:
        self.runs += 1
        self.trajectories.append(np.asarray(q_deg, dtype=float).copy())
        rows = []
        n = len(q_deg)
        for k in range(n):
            if cancel is not None and cancel.is_set():
                break
            cmd = np.asarray(q_deg[k], dtype=float)
            prev = self.pos.copy()
            stalled = self.stall_after_s is not None and self.time_s >= self.stall_after_s
            if not stalled:
                self.pos = self.pos + self.alpha * (cmd - self.pos)
            step = self.plant.step(self.period_s, self.pos.copy())  # type: ignore[attr-defined]
            velocity = (self.pos - prev) / self.period_s
            current = (self.amps_per_Nm * np.asarray(step.knob_torque_Nm)
                       + self.motor_friction_A * np.tanh(velocity / 2.0)
                       + self.rng.normal(0.0, self.noise, 2))
            if self.spike_rate:
                spikes = self.rng.random(2) < self.spike_rate
                current = current + spikes * self.rng.choice([-1, 1], 2) * 0.3
            self.time_s += self.period_s
            rows.append([self.time_s, *cmd, *cmd, *self.pos, *current, *step.tip_deg])
            if progress is not None and k % 250 == 0:
                progress(k / n)
        data = np.array(rows, dtype=float).reshape(-1, 11)
        names = ("t", "q1", "q2", "cmd1", "cmd2", "pos1", "pos2", "cur1", "cur2", "tip1", "tip2")
        order = (0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10)
        return Recording({name: data[:, j].copy() for name, j in zip(names, order, strict=True)},
                         {"source": "LockstepPlantRunner"})


def sweep_recording(sweep: object, runner: LockstepPlantRunner | None = None,
                    period_s: float = 0.004) -> Recording:
    """One protocol sweep (with its move to -A) on the built-in plant, with its metadata."""
    from simrig.plants.capstan.tendon_sheath import make_tendon_sheath_plant
    from tsmd.calibration.player import sweep_metadata
    from tsmd.calibration.protocol import Protocol, sweep_run

    runner = runner or LockstepPlantRunner(make_tendon_sheath_plant(), period_s)
    run = sweep_run(sweep, np.zeros(2), period_s,  # type: ignore[arg-type]
                    Protocol("t", (sweep,)))  # type: ignore[arg-type]
    rec = runner.run(run.t_s, run.q_deg)
    rec.metadata.update(sweep_metadata(sweep, float(run.t_s[run.sweep_start])))  # type: ignore
    return rec
