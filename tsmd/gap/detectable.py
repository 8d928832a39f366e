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
from numpy.typing import NDArray

from simrig.current_sensor import CurrentSensor
from tsmd.gap.contrast import TestData, collect_tests
from tsmd.gap.data import series_from_recording
from tsmd.gap.dwell import dwell_slope
from tsmd.gap.loops import contrast_of, loop_contrast
from tsmd.gap.presets import PlantSpec
from tsmd.gap.reference import measured_windows
from tsmd.gap.selftest import EFFECTS, drive_plant, trajectory
from tsmd.gap.session import make_session

FloatArray = NDArray[np.float64]


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


def condition_footprint(data: PlantSpec, case: str, unit: int, rate_hz: float,
                        unit_variation: float = 0.1) -> Footprint:
    """The footprint of a rate or creep case where the effect is defined (session 17), on the
    protocol (noise-free, both configurations, effect on minus off): a rate dependence on the
    fast-minus-slow loop contrast of the tips and currents (RMS over the matched points), creep
    on the loaded-minus-unloaded drift over a held dwell (RMS over the dwell pairs). Such a
    case's physics may move the tip over the whole motion far more than it changes with speed
    or at a held knob: stickslip's fast relaxation branch x5 moves unit 1's tip 1.1 deg but its
    speed contrast 0.09 deg, its slow branch x1.5 the tip 0.38 deg but the currents' drift over
    a dwell 3.3 mA; nobody can name those from the data."""
    def measured(which: str) -> dict[str, TestData]:
        recs = make_session(data, which, 4.0, rate_hz, unit, unit_variation, 0.0, 0.0)
        series = [series_from_recording(r, f"footprint-{i}") for i, r in enumerate(recs)
                  if "segments" in r.metadata]
        tests = collect_tests(series, [measured_windows(s) for s in series])
        return {config: by_test["creep" if case == "creep" else "rate"]
                for config, by_test in tests.items()}

    off, on = measured("none"), measured(case)
    read = _dwell_drifts if case == "creep" else _speed_contrasts
    (tip0, cur0), (tip1, cur1) = read(off), read(on)
    return Footprint(float(np.sqrt(np.mean((tip1 - tip0) ** 2))),
                     float(np.sqrt(np.mean((cur1 - cur0) ** 2))))


def _speed_contrasts(tests: dict[str, TestData]) -> tuple[FloatArray, FloatArray]:
    """Per configuration the rate test's level contrast of the tips and of the currents."""
    tip: list[FloatArray] = []
    cur: list[FloatArray] = []
    for t in tests.values():
        for found, out in ((loop_contrast(t.loops, t.levels), tip),
                           (loop_contrast(t.currents, t.levels), cur)):
            if found is not None:
                out.append(contrast_of(found))
    return np.asarray(tip, dtype=np.float64), np.asarray(cur, dtype=np.float64)


def _dwell_drifts(tests: dict[str, TestData]) -> tuple[FloatArray, FloatArray]:
    """Per configuration and dwell pair how far each channel moves over the loaded dwell beyond
    the unloaded one (loaded-minus-unloaded slope times the loaded dwell's length)."""
    rows = []
    for t in tests.values():
        for rep in sorted({r for _, r in t.dwells}):
            loaded, unloaded = t.dwells.get(("loaded", rep)), t.dwells.get(("unloaded", rep))
            if loaded is None or unloaded is None:
                continue
            (tl, yl), (tu, yu) = loaded, unloaded
            rows.append([(dwell_slope(tl, yl[:, ch])[0] - dwell_slope(tu, yu[:, ch])[0])
                         * float(tl[-1] - tl[0]) for ch in range(4)])
    found = np.array(rows, dtype=float).reshape(-1, 4)
    return found[:, :2], found[:, 2:]
