"""Self-test: diagnose 'real' data made by the built-in plant with one effect the simulator lacks.

The data are made by driving the capstan plant (``simrig.plants.capstan``) directly with a knob
trajectory, bypassing CAN and the drive: the knob follows the command exactly, the tip is read
by the simulated EM tracker and the motor current is ``torque / (gear * kt)`` plus motor Coulomb
friction, read through the plant package's :class:`CurrentSensor` (noise, offset and, for the
``sensor`` case, lag). Each 'real' catheter is a different unit (slack and sheath friction
drawn +-15 % around the defaults, see :func:`unit_knobs`), so the diagnosed simulator (the same
plant with default constants, effects off) must fit its base parameters first. The plant's
effects are written independently of the candidates in :mod:`tsmd.gap.candidates`: the
diagnosis has to recognise them by their signature.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.current_sensor import CurrentSensor
from simrig.plant import load_plant
from simrig.plants.capstan import DEFAULT_KNOBS
from simrig.tracker import EmTracker
from tsmd.gap.data import series_from_recording
from tsmd.gap.diagnose import diagnose
from tsmd.gap.fit import ParamSpec
from tsmd.gap.result import GapConfig, GapResult
from tsmd.gap.score import SelftestCase, SelftestResult
from tsmd.gap.simulate import simulate
from tsmd.recording import Recording

BUILTIN_PLANT = "simrig.plants.capstan:make_tendon_sheath_plant"

BUILTIN_FIT_SPECS: tuple[ParamSpec, ...] = (
    *(ParamSpec(f"knobs.{k}.slack_pos_mm+knobs.{k}.slack_neg_mm", -1.5, 1.5, knob=k)
      for k in (0, 1)),
    *(ParamSpec(f"knobs.{k}.{name}", lo, hi, knob=k)
      for name, lo, hi in (("sheath_friction", 0.03, 0.4), ("slack_pos_mm", 0.2, 4.0),
                           ("slack_neg_mm", 0.2, 4.0))
      for k in (0, 1)))
"""Base parameters fitted for the built-in plant: dead zone (both slacks together, then each
side) and sheath friction, per knob."""

EFFECTS: dict[str, tuple[dict[str, float], float, str | None]] = {
    "none": ({}, 0.0, None),
    "coupling": ({"coupling": 0.5}, 0.0, "coupling"),
    "rate": ({"rate_dependence": 0.25}, 0.0, "rate"),
    "compliance": ({"tendon_compliance": 1.0}, 0.0, "compliance"),
    "curvature": ({"sheath_curvature_deg": 120.0}, 0.0, "curvature"),
    "sensor": ({}, 0.1, "sensor"),
    "creep": ({"creep_mm_per_N_s": 1.5e-4}, 0.0, "drift"),
}
"""Case -> (plant effect keywords, current-sensor lag s, the candidate that should win).

Strengths are chosen by the size of the effect on the tip (:func:`effect_size`: RMS of the tip
with the effect minus without, same unit and motion, over the 120 s and 300 s self-test runs of
seeds 0 and 1), so that each effect makes a tip gap of the size it made on the earlier nominal
plant (sheath friction 0.15 over 240 deg, routed handle, tendon EA 1830 N) at that plant's
nominal strengths: half the plant's nominal coupling constants, sheath friction +25 % at
100 deg/s (the nominal +100 % nearly locks the tip of the high-friction sheath), twice the
tendon compliance, a 120 deg sheath bend, a 0.1 s current filter, slack creep of 0.15 um per
newton-second. An effect whose size changed by under 20 % kept its strength (compliance; the
sensor lag, sized on the current). docs/gap.md, "Self-test strengths", has the figures."""

GEAR_RATIO = 50.0
KT_NM_PER_A = 0.03
MOTOR_COULOMB_A = 0.01


def _sweep(t: NDArray[np.float64], rate_hz: float, speed_deg_s: NDArray[np.float64],
           amp_deg: NDArray[np.float64]) -> NDArray[np.float64]:
    """Triangle sweeps of a varying amplitude, each traversed at the given knob speed."""
    phase = 2 * np.pi * np.cumsum(speed_deg_s / (4.0 * amp_deg)) / rate_hz
    return amp_deg * (2 / np.pi) * np.arcsin(np.sin(phase))


def trajectory(duration_s: float, rate_hz: float) -> tuple[NDArray[np.float64],
                                                            NDArray[np.float64]]:
    """An identification experiment: both knobs sweep at several speeds and amplitudes.

    Knob 1 sweeps at 6 to 80 deg/s (log-spaced, a full cycle of speeds every 60 s) with
    amplitudes 35 to 85 deg; knob 2 sweeps more slowly (4 to 40 deg/s, amplitudes 30 to 70 deg)
    on incommensurate periods, so every speed and load of one knob is seen with the other knob
    at many angles. One speed, one amplitude or a fixed other knob would leave rate dependence,
    compliance and coupling without a signature the base fit cannot absorb.
    """
    t = np.arange(0.0, duration_s, 1.0 / rate_hz)
    v1 = 6.0 * (80.0 / 6.0) ** (0.5 - 0.5 * np.cos(2 * np.pi * t / 60.0))
    a1 = 60.0 + 25.0 * np.sin(2 * np.pi * t / 37.0)
    v2 = 4.0 * 10.0 ** (0.5 - 0.5 * np.cos(2 * np.pi * t / 83.0 + 1.0))
    a2 = 50.0 + 20.0 * np.sin(2 * np.pi * t / 53.0 + 0.7)
    return t, np.column_stack([_sweep(t, rate_hz, v1, a1), _sweep(t, rate_hz, v2, a2)])


def single_speed_trajectory(duration_s: float, rate_hz: float) -> tuple[NDArray[np.float64],
                                                                         NDArray[np.float64]]:
    """The earlier self-test motion, kept for comparison: knob 1 triangle sweeps +-59..85 deg at
    periods 12-40 s (7 to 24 deg/s), knob 2 one +-60 deg sine of period 47 s.

    It shows what a poorly exciting recording does to the diagnosis (docs/benchmarks.md#gap).
    """
    t = np.arange(0.0, duration_s, 1.0 / rate_hz)
    period = 26.0 + 14.0 * np.sin(2 * np.pi * t / 110.0)
    phase = 2 * np.pi * np.cumsum(1.0 / period) / rate_hz
    amp = 72.0 + 13.0 * np.sin(2 * np.pi * t / 83.0)
    q1 = amp * (2 / np.pi) * np.arcsin(np.sin(phase))
    q2 = 60.0 * np.sin(2 * np.pi * t / 47.0 + 0.4)
    return t, np.column_stack([q1, q2])


TRAJECTORIES = {"experiment": trajectory, "single-speed": single_speed_trajectory}
"""Self-test motions by name (``--trajectory``)."""


def unit_knobs(seed: int, variation: float,
               defaults: Sequence[Any] | None = None) -> list[dict[str, float]]:
    """One catheter unit: slack per side and sheath friction off the defaults by +-variation.

    Only the base parameters the diagnosis fits are varied, so that what remains after the base
    fit is the effect put in (plus noise). ``defaults``: the plant's per-knob constants (default:
    the built-in plant's ``DEFAULT_KNOBS``).
    """
    rng = np.random.default_rng(1000 + seed)
    names = ("slack_pos_mm", "slack_neg_mm", "sheath_friction")
    return [{k: float(getattr(knob, k)) * (1.0 + variation * rng.uniform(-1, 1)) for k in names}
            for knob in (DEFAULT_KNOBS if defaults is None else defaults)]


def drive_plant(plant: Any, q: NDArray[np.float64], rate_hz: float,
                max_step_s: float = 0.0) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Step a plant along knob angles ``q`` (rows x 2); returns the true tip angle (deg) and the
    true motor current (A: torque / (gear * kt) plus motor Coulomb friction), both noise-free.
    With ``max_step_s`` shorter than a row, the plant is stepped that finely along the knobs'
    straight lines between rows and read at the rows (a plant valid only at short steps)."""
    sub = int(np.ceil(1.0 / (rate_hz * max_step_s) - 1e-9)) if max_step_s > 0.0 else 1
    if sub > 1 and len(q) > 1:
        rows = np.arange(len(q), dtype=float)
        fine = np.arange((len(q) - 1) * sub + 1) / sub
        q_fine = np.stack([np.interp(fine, rows, q[:, j]) for j in range(q.shape[1])], axis=1)
        tip, cur = drive_plant(plant, q_fine, rate_hz * sub)
        return tip[::sub], cur[::sub]
    tip, torque = simulate(plant, np.arange(len(q)) / rate_hz, q)
    vel = np.diff(q, axis=0, prepend=q[:1]) * rate_hz
    return tip, torque / (GEAR_RATIO * KT_NM_PER_A) + MOTOR_COULOMB_A * np.tanh(vel / 0.5)


@dataclass
class EffectSize:
    """How much one injected effect moves the plant's outputs, before any diagnosis."""

    case: str
    duration_s: float
    seed: int
    tip_rmse_deg: float
    """RMS over both knobs and all rows of (tip with the effect - tip without), noise-free."""
    tip_max_deg: float
    cur_rmse_A: float
    """The same for the true motor current (the sensor lag applied for the ``sensor`` case)."""


def effect_size(case: str, duration_s: float, seed: int, rate_hz: float = 50.0,
                effects: dict[str, float] | None = None, lag_s: float | None = None,
                plant_spec: str = BUILTIN_PLANT, unit_variation: float = 0.15,
                motion: str = "experiment") -> EffectSize:
    """The size of an effect on one self-test unit: same unit and motion, effect on vs off.

    This is the criterion the self-test strengths are chosen by (a gap of a given size on the
    tip), independent of what the diagnosis makes of it. ``effects``/``lag_s`` default to the
    case's entry in :data:`EFFECTS`; ``plant_spec`` lets another plant version be measured.
    """
    case_effects, case_lag_s, _ = EFFECTS[case]
    eff = case_effects if effects is None else effects
    lag = case_lag_s if lag_s is None else lag_s
    module = importlib.import_module(plant_spec.partition(":")[0])
    knobs = unit_knobs(seed, unit_variation, module.DEFAULT_KNOBS)
    _t, q = TRAJECTORIES[motion](duration_s, rate_hz)
    tip0, cur0 = drive_plant(load_plant(plant_spec, {"knobs": knobs}), q, rate_hz)
    tip1, cur1 = drive_plant(load_plant(plant_spec, {"knobs": knobs, **eff}), q, rate_hz)
    if lag > 0.0:
        sensors = [CurrentSensor(lag_s=lag) for _ in range(2)]
        cur1 = np.array([[sensors[j].measure(1.0 / rate_hz, float(row[j])) for j in range(2)]
                         for row in cur1])
    dtip = tip1 - tip0
    return EffectSize(case, duration_s, seed, float(np.sqrt(np.mean(dtip**2))),
                      float(np.max(np.abs(dtip))), float(np.sqrt(np.mean((cur1 - cur0) ** 2))))


def make_real_recording(case: str, duration_s: float, rate_hz: float, seed: int,
                        unit_variation: float = 0.15, tip_noise_deg: float = 0.1,
                        current_noise_A: float = 0.004,
                        motion: str = "experiment") -> Recording:
    """A 'real' recording of one case (see the module docstring for how it is made)."""
    effects, lag_s, _ = EFFECTS[case]
    plant = load_plant(BUILTIN_PLANT, {"knobs": unit_knobs(seed, unit_variation), **effects})
    t, q = TRAJECTORIES[motion](duration_s, rate_hz)
    tracker = EmTracker(noise_deg=tip_noise_deg, seed=seed)
    sensors = [CurrentSensor(lag_s=lag_s, offset_A=0.003 * (1 - 2 * k), noise_A=current_noise_A,
                             seed=seed * 7 + k) for k in range(2)]
    dt = 1.0 / rate_hz
    true_tip, true_A = drive_plant(plant, q, rate_hz)
    tip = np.empty_like(q)
    cur = np.empty_like(q)
    for k in range(len(t)):
        tip[k] = tracker.measure(true_tip[k])
        cur[k] = [sensors[j].measure(dt, float(true_A[k, j])) for j in range(2)]
    cols = {"t": t, "q1": q[:, 0], "q2": q[:, 1], "cmd1": q[:, 0], "cmd2": q[:, 1],
            "pos1": q[:, 0], "pos2": q[:, 1], "cur1": cur[:, 0], "cur2": cur[:, 1],
            "tip1": tip[:, 0], "tip2": tip[:, 1]}
    return Recording({k: np.array(v, dtype=float) for k, v in cols.items()},
                     {"source": f"gap selftest case {case} seed {seed}",
                      "note": "plant driven directly, CAN and drive bypassed"})


def builtin_factory(base_params: dict[str, Any] | None = None) -> Callable[[dict[str, Any]],
                                                                              Any]:
    """Factory of the diagnosed simulator: the built-in plant with the given parameters."""
    fixed = dict(base_params or {})

    def factory(params: dict[str, Any]) -> Any:
        return load_plant(BUILTIN_PLANT, complete_knobs({**fixed, **params}))

    return factory


def complete_knobs(params: dict[str, Any]) -> dict[str, Any]:
    """The built-in plant wants both knobs listed: pad ``knobs`` set for knob 1 only."""
    knobs = params.get("knobs")
    if isinstance(knobs, list) and len(knobs) < 2:
        params = {**params, "knobs": [*knobs, *({} for _ in range(2 - len(knobs)))]}
    return params


def _tip_rmse(m: dict[str, float] | None) -> float | None:
    if m is None:
        return None
    return float(np.sqrt(np.nanmean([m["tip1_rmse_deg"] ** 2, m["tip2_rmse_deg"] ** 2])))


def _cur_rmse(m: dict[str, float] | None) -> float | None:
    if m is None:
        return None
    return float(np.sqrt(np.nanmean([m["cur1_rmse_A"] ** 2, m["cur2_rmse_A"] ** 2])))


def run_case(case: str, duration_s: float, seed: int, rate_hz: float = 50.0,
             config: GapConfig | None = None,
             motion: str = "experiment") -> tuple[SelftestCase, GapResult]:
    """Make one 'real' recording and diagnose it blind (the case is not passed on)."""
    rec = make_real_recording(case, duration_s, rate_hz, seed, motion=motion)
    series = series_from_recording(rec, f"{case}-{seed}")
    cfg = config or GapConfig(fit_specs=BUILTIN_FIT_SPECS, seed=seed)
    start = time.perf_counter()
    result = diagnose([series], builtin_factory(), {}, cfg)
    wall = time.perf_counter() - start
    top = result.top[0] if result.top else None
    share = next((c.share for c in result.candidates if c.name == top), None)
    before_tip = _tip_rmse(result.before)
    before_cur = _cur_rmse(result.before)
    assert before_tip is not None and before_cur is not None
    return SelftestCase(case, duration_s, seed, EFFECTS[case][2], result.verdict, top, share,
                        before_tip, _tip_rmse(result.after_top), before_cur,
                        _cur_rmse(result.after_top), wall), result


def run_selftest(cases: Sequence[str], sizes_s: Sequence[float], seeds: Sequence[int],
                 rate_hz: float = 50.0, config: GapConfig | None = None,
                 progress: Callable[[SelftestCase], None] | None = None,
                 motion: str = "experiment") -> SelftestResult:
    result = SelftestResult()
    for size in sizes_s:
        for seed in seeds:
            for case in cases:
                c, _ = run_case(case, size, seed, rate_hz, config, motion)
                result.cases.append(c)
                if progress is not None:
                    progress(c)
    return result
