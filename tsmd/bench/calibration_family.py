"""The calibration on a family of simulated catheters: acceptance, accuracy against the tip,
wall time split between the stack and the plant, and refusal of injected faults.

One *run* is one catheter (a plant built with a unit seed) and one noise seed (current sensor
and tracker). Each run plays the chosen protocols on fresh rigs; the truth at each of the
paper's 7 grid points per knob is read off the tracked tip of the paper protocol's sweep there
(:func:`tsmd.bench.tip_truth.tip_truth`), or, when the paper protocol is not run, of the
same sweeps played on the plant alone (:func:`truth_sweeps`), so every profile is judged on the
same 56 values per catheter (the fast one interpolated over the other knob's angle as the
profile is, pchip).
"""

from __future__ import annotations

import dataclasses
import math
import resource
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import PchipInterpolator

from simrig.plant import Plant, PlantStep, as_plant_step, load_plant
from tsmd.bench.tip_truth import tip_truth
from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.errors import CalibrationError
from tsmd.calibration.identify import PARAMETERS
from tsmd.calibration.player import sweep_metadata
from tsmd.calibration.protocol import Protocol, fast_protocol, paper_protocol, sweep_run
from tsmd.calibration.run import device_options, finish, run_sweeps
from tsmd.config import TsmdConfig, default_sim_config
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
    """The same against the line truth (:data:`tsmd.bench.tip_truth.TRUTHS`)."""

    @property
    def within(self) -> int:
        return int(np.sum(np.asarray(self.errors) <= TARGET_DEG))

    @property
    def max_error(self) -> float:
        e = np.asarray(self.errors, dtype=float)
        return float(np.nanmax(e)) if np.isfinite(e).any() else math.nan


Inject = Callable[[Any], None]
"""Called with the runner before the protocol starts (fault injection)."""


def unit_config(base: TsmdConfig, plant: str, params: dict[str, Any], unit_key: str,
                unit: int) -> TsmdConfig:
    """The sim config of one catheter of the family."""
    sim = dataclasses.replace(base.sim, plant=plant, params={**params, unit_key: unit})
    return base.replace(sim=sim)


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
            runs = run_sweeps(runner, proto, options=device_options(None, device), omegas=omegas)
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


@dataclass
class CatheterRun:
    """Both protocols on one catheter with one noise seed."""

    plant: str
    unit: int
    noise_seed: int
    runs: dict[str, ProtocolRun]
    peak_rss_MiB: float


def run_catheter(plant: str, params: dict[str, Any], unit_key: str, unit: int, noise_seed: int,
                 device: DeviceModel, protocols: Sequence[str] = ("paper", "fast"),
                 config: TsmdConfig | None = None) -> CatheterRun:
    """The paper protocol (it gives the truth) and the others on one catheter."""

    cfg = unit_config(config or default_sim_config(), plant, params, unit_key, unit)
    makers = {"paper": paper_protocol, "fast": fast_protocol}
    runs = {name: play_protocol(cfg, device, makers[name](), noise_seed) for name in protocols}
    paper = runs.get("paper")
    full = paper is not None and len(paper.points) == len(paper_protocol().sweeps)
    truth_points = paper.points if full and paper else truth_sweeps(cfg)
    truth = {(p.knob, p.other_deg): tip_truth(p) for p in truth_points}
    truth_lines = {(p.knob, p.other_deg): tip_truth(p, "lines") for p in truth_points}
    for run in runs.values():
        score(run, truth, truth_lines)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return CatheterRun(plant, unit, noise_seed,
                       {k: v for k, v in runs.items() if k in protocols}, rss)


def family_table(results: Sequence[CatheterRun], protocol: str) -> str:
    """One row per catheter and noise seed, then the family's figures and the worst unit."""
    head = ["unit", "noise seed", "accepted", "re-sweeps", "sweeping (s)",
            f"within {TARGET_DEG:g} deg", "max error (deg)", "wall (s)", "plant share"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    rows = [(c, c.runs[protocol]) for c in results if protocol in c.runs]
    for c, r in rows:
        share = r.plant_s / r.wall_s if r.wall_s > 0 else math.nan
        lines.append(
            f"| {c.unit} | {c.noise_seed} | {'yes' if r.accepted else 'NO'} | "
            f"{len(r.resweeps)} | {r.sweep_time_s:.0f} | {r.within}/{len(r.errors)} | "
            f"{r.max_error:.2f} | {r.wall_s:.1f} | {share:.0%} |")
    if not rows:
        return "(no runs)"
    accepted = sum(r.accepted for _, r in rows)
    good = sum(r.within >= 0.95 * len(r.errors) for _, r in rows)
    under3 = sum(r.max_error <= LIMIT_DEG for _, r in rows)
    values = np.concatenate([np.asarray(r.errors, float) for _, r in rows])
    worst_c, worst = min(rows, key=lambda cr: (cr[1].within, -cr[1].max_error))
    lines += [
        "",
        f"- accepted: {accepted} of {len(rows)} runs ({accepted / len(rows):.0%})",
        f"- runs with >= 95 % of the values within {TARGET_DEG:g} deg: {good} of {len(rows)}; "
        f"with none beyond {LIMIT_DEG:g} deg: {under3} of {len(rows)}",
        f"- all values: {int(np.sum(values <= TARGET_DEG))} of {values.size} within "
        f"{TARGET_DEG:g} deg, mean |error| {np.nanmean(values):.2f} deg, max "
        f"{np.nanmax(values):.2f} deg",
        f"- worst: unit {worst_c.unit} noise seed {worst_c.noise_seed}: {worst.within}/"
        f"{len(worst.errors)} within {TARGET_DEG:g} deg, max {worst.max_error:.2f} deg"
        + ("" if worst.accepted else f", refused: {worst.reason[:200]}"),
    ]
    lines += line_truth_summary(rows)
    refused = [(c, r) for c, r in rows if not r.accepted]
    lines += [f"- refused: unit {c.unit} seed {c.noise_seed}: {r.reason[:300]}"
              for c, r in refused]
    return "\n".join(lines)


def line_truth_summary(rows: Sequence[tuple[CatheterRun, ProtocolRun]]) -> list[str]:
    """The family's figures again against the line truth (where the runs carry it)."""
    scored = [(c, r) for c, r in rows if r.errors_lines]
    if not scored:
        return []
    values = np.concatenate([np.asarray(r.errors_lines, float) for _, r in scored])
    good = sum(int(np.sum(np.asarray(r.errors_lines) <= TARGET_DEG)) >= 0.95 * len(r.errors_lines)
               for _, r in scored)
    return [f"- against the line truth (corners of the paper's lines on the tip): "
            f"{int(np.sum(values <= TARGET_DEG))} of {values.size} within {TARGET_DEG:g} deg, "
            f"runs >= 95 %: {good} of {len(scored)}, max {np.nanmax(values):.2f} deg"]


def run_catheter_summary(plant: str, params: dict[str, Any], unit_key: str, unit: int,
                         noise_seed: int, device: DeviceModel,
                         protocols: Sequence[str] = ("paper", "fast")) -> CatheterRun:
    """:func:`run_catheter` without the recordings and signals (small to send between
    processes): the verdicts, the estimates and the errors."""
    result = run_catheter(plant, params, unit_key, unit, noise_seed, device, protocols)
    for run in result.runs.values():
        run.points = [dataclasses.replace(p, recording=None) for p in run.points]
    return result
