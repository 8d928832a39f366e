"""Unhealthy catheters and drives for `tsmd bench calibration --unhealthy`.

Each fault is injected through the simulated drive (its current sensor, its motor) or the
plant (a wrapper between the motor and the catheter), never through the calibration. The fast
protocol then runs; the calibration must refuse, naming the reason.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.plant import Plant, PlantStep, as_plant_step
from tsmd.bench.calibration_family import unit_config
from tsmd.calibration.protocol import fast_protocol
from tsmd.config import default_sim_config
from tsmd.profile import DeviceModel
from tsmd.tracked_calibration import play_protocol


class _Sensor:
    """Wraps a drive's current sensor: zero, stuck after a while, or clipped throughout."""

    def __init__(self, inner: Any, kind: str, after_ticks: int = 20_000,
                 clip_A: float = 0.12) -> None:
        self.inner = inner
        self.kind = kind
        self.after = after_ticks
        self.clip_A = clip_A
        self.ticks = 0
        self.last = 0.0

    def measure(self, dt_s: float, current_A: float) -> float:
        value = float(self.inner.measure(dt_s, current_A))
        self.ticks += 1
        if self.kind == "zero":
            return 0.0
        if self.kind == "stuck" and self.ticks > self.after:
            return self.last
        self.last = value
        if self.kind == "clipped":
            # A sensor whose range ends below the load (the sim's loaded current reaches about
            # 0.25 A at the ends of the travel).
            return max(-self.clip_A, min(self.clip_A, value))
        return value


class _KnobFault:
    """Between the motor and the catheter of knob 0: a tendon that broke (no load ever), a
    coupling that slips when loaded (stick-slip), or a knob geared down (the dead zone then
    spans most of the travel)."""

    def __init__(self, plant: Plant, kind: str, slip_Nm: float = 0.12, slip_deg: float = 4.0,
                 gear: float = 0.27) -> None:
        self.plant = plant
        self.kind = kind
        self.slip_Nm = slip_Nm
        self.slip_deg = slip_deg
        self.gear = gear
        self.offset_deg = 0.0
        self.previous_deg = 0.0

    def reset(self) -> None:
        self.plant.reset()
        self.offset_deg = 0.0

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        knob = np.array(knob_deg, dtype=float)
        moving = knob[0] - self.previous_deg
        self.previous_deg = float(knob[0])
        if self.kind == "geared":
            knob[0] *= self.gear
        knob[0] -= self.offset_deg
        out = as_plant_step(self.plant.step(dt_s, knob))
        torque = np.array(out.knob_torque_Nm, dtype=float)
        if self.kind == "broken":
            torque[0] = 0.0
        elif self.kind == "slip" and abs(torque[0]) > self.slip_Nm and moving != 0.0:
            self.offset_deg += math.copysign(self.slip_deg, moving)
        return PlantStep(out.tip_deg, torque)


def _sensor_fault(kind: str, **kw: Any) -> Callable[[Any], None]:
    def inject(runner: Any) -> None:
        rig = runner.rig
        rig.sensors[0] = _Sensor(rig.sensors[0], kind, **kw)
    return inject


def _jam(after_ticks: int) -> Callable[[Any], None]:
    """The motor of knob 0 jams after a while (the drive reports the following error)."""
    def inject(runner: Any) -> None:
        rig = runner.rig
        motor = rig.motors[0]
        original = motor.step
        count = [0]

        def step(target_deg: float, powered: bool) -> float:
            count[0] += 1
            if count[0] > after_ticks:
                motor.jammed = True
            return float(original(target_deg, powered))
        motor.step = step
    return inject


FAULTS: dict[str, tuple[str, dict[str, Any]]] = {
    "no current feedback (sensor reads 0)": ("sensor", {"kind": "zero"}),
    "current sensor stuck": ("sensor", {"kind": "stuck"}),
    "current sensor saturated (clipped)": ("sensor", {"kind": "clipped"}),
    "motor stalls (jams)": ("jam", {"after_ticks": 20_000}),
    "knob slips under load": ("plant", {"kind": "slip"}),
    "tendon broken (never leaves the dead zone)": ("plant", {"kind": "broken"}),
    "dead zone beyond the plausible range": ("plant", {"kind": "geared"}),
}


def fault_table(plant: str, params: dict[str, Any], unit_key: str, unit: int, noise_seed: int,
                device: DeviceModel, only: Sequence[str] | None = None) -> str:
    """Run each fault (or those whose label contains one of ``only``); one row each: refused
    or not, and the reason given."""
    cfg = unit_config(default_sim_config(), plant, params, unit_key, unit)
    lines = ["| fault | refused | reason given |", "|---|---|---|"]
    refused = 0
    chosen = {k: v for k, v in FAULTS.items() if only is None or any(o in k for o in only)}
    for label, (where, kw) in chosen.items():
        inject = None
        wrap = None
        if where == "sensor":
            inject = _sensor_fault(**kw)
        elif where == "jam":
            inject = _jam(**kw)
        else:
            def wrap(p: Plant, kw: dict[str, Any] = kw) -> Plant:
                return _KnobFault(p, **kw)
        run = play_protocol(cfg, device, fast_protocol(), noise_seed, inject=inject, wrap=wrap)
        refused += not run.accepted
        reason = run.reason.replace("|", "/")[:400] if not run.accepted else "(accepted)"
        lines.append(f"| {label} | {'yes' if not run.accepted else 'NO'} | {reason} |")
    lines.append(f"\n- refused {refused} of {len(chosen)}")
    return "\n".join(lines)
