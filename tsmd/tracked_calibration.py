"""A calibration played on a tracked simulated unit and scored against its tip.

The calibration itself sees only motor position and current; the tip is read afterwards as
the truth (:func:`tsmd.tip_truth.tip_truth`). Used by the family benchmark and by the data
sheet's choice of backlash rule, where the manufacturer tracks the sheet's own unit anyway, so
neither the sheet nor the bench owns it.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import PchipInterpolator

from simrig.plant import Plant, PlantStep, as_plant_step, load_plant
from tsmd.calibration.assemble import GridPoint, QualityLimits
from tsmd.calibration.errors import CalibrationError
from tsmd.calibration.estimate import KINDS, Estimate
from tsmd.calibration.player import sweep_metadata
from tsmd.calibration.protocol import Protocol, paper_protocol, sweep_run
from tsmd.calibration.resweep import point_estimates
from tsmd.calibration.run import device_options, finish, run_sweeps
from tsmd.calibration.sweep_result import PARAMETERS
from tsmd.config import TsmdConfig
from tsmd.profile import DeviceModel
from tsmd.recording import Recording
from tsmd.replay import LockstepRunner

TARGET_DEG = 2.0
LIMIT_DEG = 3.0


class TimedPlant:
    """A plant that counts the time spent in its own ``step`` (the rest of a tick is stack)."""

    def __init__(self, plant: Plant) -> None:
        self.plant = plant
        self.step_s = 0.0
        self.steps = 0

    def reset(self) -> None:
        self.plant.reset()

    def step(self, dt_s: float, knob_deg: NDArray[np.float64]) -> PlantStep:
        t0 = time.perf_counter()
        out = as_plant_step(self.plant.step(dt_s, knob_deg))
        self.step_s += time.perf_counter() - t0
        self.steps += 1
        return out


@dataclass
class ProtocolRun:
    """One protocol on one catheter: verdict, values, timing."""

    protocol: str
    accepted: bool
    reason: str
    points: list[GridPoint]
    resweeps: list[str]
    sweep_time_s: float
    wall_s: float
    plant_s: float
    ticks: int
    errors: list[float] = field(default_factory=list)
    """|identified - tip| for the 56 values (NaN where either is missing)."""
    errors_lines: list[float] = field(default_factory=list)
    """The same against the line truth (:data:`tsmd.tip_truth.TRUTHS`)."""
    coverage: dict[str, tuple[int, int]] = field(default_factory=dict)
    """Per kind of parameter (:data:`tsmd.calibration.estimate.KINDS`): how many of the values
    measured at a grid point have the tip's truth within their reported 95 % half-width, of how
    many (:func:`coverage_against`)."""

    @property
    def within(self) -> int:
        return int(np.sum(np.asarray(self.errors) <= TARGET_DEG))

    @property
    def max_error(self) -> float:
        e = np.asarray(self.errors, dtype=float)
        return float(np.nanmax(e)) if np.isfinite(e).any() else math.nan


Inject = Callable[[Any], None]
"""Called with the runner before the protocol starts (fault injection)."""


def play_protocol(config: TsmdConfig, device: DeviceModel, proto: Protocol, noise_seed: int,
                  inject: Inject | None = None,
                  wrap: Callable[[Plant], Plant] | None = None) -> ProtocolRun:
    """Run one protocol through the full stack in lockstep, identify, check; never raises for
    a refusal (the reason is returned)."""

    plant = TimedPlant(load_plant(config.sim.plant, config.sim.params))
    runs = None
    t0 = time.monotonic()
    omegas = tuple(k.omega for k in device.knobs)
    try:
        with LockstepRunner(config, seed=noise_seed,
                            plant=wrap(plant) if wrap else plant) as runner:
            if inject is not None:
                inject(runner)
            runs = run_sweeps(runner, proto, options=device_options(None, device), omegas=omegas,
                              refuse_tip_error_deg=QualityLimits().refuse_tip_error_deg)
        finish("bench", device, runs.points, amplitude_deg=90.0)
        accepted, reason = True, ""
    except CalibrationError as exc:
        accepted, reason = False, str(exc)
    except Exception as exc:  # the rig itself failed (e.g. a drive fault that stops the run)
        accepted, reason = False, f"{type(exc).__name__}: {exc}"
    wall = time.monotonic() - t0
    return ProtocolRun(proto.name, accepted, reason, runs.points if runs else [],
                       runs.resweeps if runs else [],
                       proto.sweep_time_s + (runs.resweep_time_s if runs else 0.0), wall,
                       plant.step_s, plant.steps)


def profile_values(points: Sequence[GridPoint], knob: int, name: str,
                   at_deg: Sequence[float]) -> NDArray[np.float64]:
    """A parameter over the other knob's angle as the profile holds it (pchip between the
    grid points), at ``at_deg``."""
    found = sorted((p.other_deg, p.result.estimate(name)) for p in points if p.knob == knob)
    finite = [(x, y) for x, y in found if math.isfinite(y)]
    if len(finite) < 2:
        return np.full(len(at_deg), math.nan)
    x, y = zip(*finite, strict=True)
    return np.asarray(PchipInterpolator(x, y, extrapolate=True)(np.asarray(at_deg)), float)


def errors_against(run: ProtocolRun, truth: dict[tuple[int, float], dict[str, float]]
                   ) -> list[float]:
    """The 56 values' |identified - tip| against one truth."""
    out = []
    for knob in (0, 1):
        grid = sorted(o for k, o in truth if k == knob)
        for name in PARAMETERS:
            found = profile_values(run.points, knob, name, grid)
            for other, value in zip(grid, found, strict=True):
                out.append(abs(value - truth[(knob, other)].get(name, math.nan)))
    return out


def score(run: ProtocolRun, truth: dict[tuple[int, float], dict[str, float]],
          truth_lines: dict[tuple[int, float], dict[str, float]] | None = None) -> None:
    """Fill ``run.errors`` (and ``run.errors_lines`` when the line truth is given)."""
    run.errors = errors_against(run, truth)
    run.errors_lines = errors_against(run, truth_lines) if truth_lines is not None else []
    run.coverage = coverage_against(run.points, truth)


def named_value_errors(points: Sequence[GridPoint],
                       truth: dict[tuple[int, float], dict[str, float]]
                       ) -> Iterator[tuple[int, str, str, float, Estimate]]:
    """Per value measured at a grid point with a tip truth: (knob, kind of parameter, its name,
    identified minus tip, its estimate). Shared by the coverage score and the sheet's sample
    (:mod:`tsmd.datasheet_sample`)."""
    for p, est in zip(points, point_estimates(points), strict=True):
        tip = truth.get((p.knob, float(p.other_deg)), {})
        for kind, names in KINDS.items():
            for name in names:
                error = est[name].value - tip.get(name, math.nan)
                if math.isfinite(error):
                    yield p.knob, kind, name, error, est[name]


def value_errors(points: Sequence[GridPoint], truth: dict[tuple[int, float], dict[str, float]]
                 ) -> Iterator[tuple[int, str, float, Estimate]]:
    """:func:`named_value_errors` without the parameter's name."""
    for knob, kind, _, error, est in named_value_errors(points, truth):
        yield knob, kind, error, est


def coverage_against(points: Sequence[GridPoint],
                     truth: dict[tuple[int, float], dict[str, float]]
                     ) -> dict[str, tuple[int, int]]:
    """Per kind of parameter: (values whose |identified - tip| is within the reported 95 %
    half-width, values scored), over the grid points the protocol measured (the half-width is
    said per grid point, not between them). An honest half-width covers about 95 %."""
    out = {kind: (0, 0) for kind in KINDS}
    for _, kind, error, est in value_errors(points, truth):
        covered, n = out[kind]
        out[kind] = (covered + int(abs(error) <= est.reported_u95_deg), n + 1)
    return out


def truth_sweeps(config: TsmdConfig) -> list[GridPoint]:
    """Without the paper protocol's run: its sweeps applied to a fresh plant of the unit
    directly as knob angles, only to read the noise-free tip. Cheaper than the full stack,
    whose servo lag only shifts the knob by a fraction of a degree; D and B are read against
    the knob angle either way."""

    proto = paper_protocol()
    period = config.loop.period_s
    plant = load_plant(config.sim.plant, config.sim.params)
    plant.reset()
    points = []
    q_now = np.zeros(2)
    for one in proto.sweeps:
        run = sweep_run(one, q_now, period, proto)
        tip: NDArray[np.float64] = np.array(
            [as_plant_step(plant.step(period, q)).tip_deg for q in run.q_deg], dtype=float)
        columns = {"t": run.t_s.copy()}
        for k in (1, 2):
            columns[f"cmd{k}"] = run.q_deg[:, k - 1].copy()
            columns[f"pos{k}"] = run.q_deg[:, k - 1].copy()
            columns[f"tip{k}"] = tip[:, k - 1].copy()
        rec = Recording(columns, sweep_metadata(one, float(run.t_s[run.sweep_start])))
        points.append(GridPoint(one.knob, one.other_deg, None,  # type: ignore[arg-type]
                                rec))
        q_now = run.q_deg[-1].copy()
    return points
