"""Whether an injected self-test effect leaves anything to find: its footprint against the noise.

A self-test case puts an effect into a plant's physics at a strength sized on the plant's
nominal unit; on some plants an effect barely reaches the signals (helixbelt's helix keeps the
tendons' length when the sheath curves: a 120 deg bend moves its tip 0.05 deg, its current 0.4
mA, against 0.1 deg and 4 mA of noise per sample). No diagnosis can name such an effect from
the data, and "none" is then the right reading. The footprint is measured on the ground truth,
for scoring only (the diagnosis never sees it): the same unit driven along the session's
identification motion with the effect on and off, noise-free, the sensor lag applied to the
current the sensor reads.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simrig.current_sensor import CurrentSensor
from tsmd.gap.presets import PlantSpec
from tsmd.gap.selftest import EFFECTS, drive_plant, trajectory


@dataclass(frozen=True)
class Footprint:
    """What one injected effect moves on one unit, before any diagnosis."""

    tip_deg: float
    """RMS over both tips and all rows of the true tip with the effect minus without."""
    cur_A: float
    """The same for the motor currents as a noise-free sensor reads them."""

    def detectable(self, tip_noise_deg: float, current_noise_A: float) -> bool:
        """At least one sample's noise on the tip or on the current: the size the diagnosis's
        own tests ask of a contrast before they name it (docs/gap.md, the size rule)."""
        return self.tip_deg >= tip_noise_deg or self.cur_A >= current_noise_A


def footprint(data: PlantSpec, case: str, unit: int, duration_s: float, rate_hz: float,
              unit_variation: float = 0.1) -> Footprint:
    """The footprint of ``case`` on ``unit`` of ``data`` over the session's identification
    motion (half its duration, as each configuration records it), in the configuration where
    the effect acts fully (the looped one: a sheath bend acts only there)."""
    _t, q = trajectory(duration_s / 2.0, rate_hz)
    off = data.build_unit(unit, unit_variation, "none")
    on = data.build_unit(unit, unit_variation, case, **data.case_effects(case))
    tip0, cur0 = drive_plant(off, q, rate_hz, data.max_step_s)
    tip1, cur1 = drive_plant(on, q, rate_hz, data.max_step_s)
    read0, read1 = (_read(cur, rate_hz, lag) for cur, lag in ((cur0, 0.0),
                                                            (cur1, EFFECTS[case][1])))
    return Footprint(float(np.sqrt(np.mean((tip1 - tip0) ** 2))),
                     float(np.sqrt(np.mean((read1 - read0) ** 2))))


def _read(current_A: np.ndarray, rate_hz: float, lag_s: float) -> np.ndarray:
    """The currents as a noise-free sensor with ``lag_s`` reads them."""
    if lag_s <= 0.0:
        return current_A
    sensors = [CurrentSensor(lag_s=lag_s) for _ in range(2)]
    return np.array([[sensors[j].measure(1.0 / rate_hz, float(row[j])) for j in range(2)]
                     for row in current_A])
