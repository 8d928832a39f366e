"""`tsmd bench accuracy`: the paper's tracking protocol through the full stack on the sim rig.

Every run goes through ``tsmd.replay.run_trajectory`` (simulated CiA 402 drives on the in-process
CAN bus, the control loop, lockstep), and compares the tip angle from the simulated EM tracker
with the desired angle. Compensators are calibrated by ``tsmd.calibration`` from motor current
when that package provides ``calibrate``; otherwise (or with ``--profile-source ground-truth``)
from D and B measured on the tracker's tip angle, and the output says so.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.analysis import measure_dead_zone_backlash
from simrig.family import PLANT_SPECS
from simrig.plants.capstan.tendon_sheath import make_tendon_sheath_plant
from tsmd import __version__
from tsmd.bench.accuracy_report import (
    METHODS,
    format_table,
    plot_runs,
    summarise,
)
from tsmd.bench.tracking_start import (
    STARTS,
    calibrate_with_plant,
    conditions,
    scenario_plant,
    start_label,
    start_of,
)
from tsmd.calibration.tension_play_fit import SweepCurrent, fit_tension_play
from tsmd.compensation import LimitedCompensator, build_compensator
from tsmd.compensation.grid import CALIBRATION_GRID_DEG
from tsmd.config import default_sim_config, resolve_data_path
from tsmd.datasheet import analysed_from, settle, tip_sweep
from tsmd.errors import TsmdError
from tsmd.profile import (
    CatheterProfile,
    load_device_model,
    load_profile,
    make_knob_profile,
    save_profile,
)
from tsmd.replay import run_trajectory
from tsmd.tracking_scenarios import (
    PERIOD_S,
    Scenario,
    conditioned,
    scenarios,
    tracking_errors,
)

# ----------------------------------------------------------------------------------------------
# Profiles


def _run(t: NDArray[np.float64], q: NDArray[np.float64], profile: Any, method: str, seed: int,
         plant: Any, fresh: bool = False) -> Any:
    config = None
    if fresh:  # the compensator is told that the plant starts never loaded
        base = default_sim_config()
        config = replace(base, compensation=replace(base.compensation, fresh_catheter=True))
    return run_trajectory(t, q, config=config, profile=profile, method=method, seed=seed,
                          plant=plant)


def make_plant(coupling: float, unit_variation: float = 0.0, unit_seed: int = 0) -> Any:
    """The simulated catheter; ``unit_variation`` > 0 draws another unit of the same product.

    The data sheet was measured on the nominal unit; other units test whether the device
    constants carry over, as they must for a real product.
    """
    params: dict[str, Any] = {}
    if coupling > 0:
        params["coupling"] = coupling
    if unit_variation > 0:
        params.update(unit_variation=unit_variation, seed=unit_seed)
    return make_tendon_sheath_plant(**params)


def ground_truth_profile(device: Any, plant_factory: Callable[[], Any], seed: int = 1000,
                         log: Callable[[str], None] = print) -> Any:
    """A profile from sweeps scored on the tracker's tip angle (not from motor current).

    The paper's calibration protocol (each knob +-90 deg at 0.04 Hz, two cycles after a
    conditioning cycle, the other knob held at each grid angle), uncompensated through the full
    stack; D and B measured on the tip with ``simrig.analysis`` (ground truth); the tension
    play's other parameters from the same sweeps' current.
    """
    knobs = []
    for knob in (0, 1):
        sweeps = []
        for other in CALIBRATION_GRID_DEG:
            tt, qq, skip = settle(*tip_sweep(knob, other, PERIOD_S), PERIOD_S)
            rec = _run(tt, qq, None, "none", seed, plant_factory())
            skip = analysed_from(skip, PERIOD_S)
            pos = rec[f"pos{knob + 1}"][skip:]
            tip = rec[f"tip{knob + 1}"][skip:]
            m = measure_dead_zone_backlash(pos, tip, threshold_deg=1.0)
            sweeps.append(SweepCurrent(other, rec["t"][skip:], rec[f"cmd{knob + 1}"][skip:],
                                       pos, rec[f"cur{knob + 1}"][skip:], m.dead_zone_pos_deg,
                                       m.dead_zone_neg_deg, m.backlash_pos_deg,
                                       m.backlash_neg_deg))
            log(f"  ground truth phi{knob + 1}, other {other:+.0f}: D {m.dead_zone_pos_deg:.1f}/"
                f"{m.dead_zone_neg_deg:.1f}  B {m.backlash_pos_deg:.1f}/{m.backlash_neg_deg:.1f}")
        dk = device.knobs[knob]
        ours = fit_tension_play(sweeps, dk)
        knobs.append(make_knob_profile(
            dk, CALIBRATION_GRID_DEG, [s.dead_zone_pos_deg for s in sweeps],
            [s.dead_zone_neg_deg for s in sweeps], [s.backlash_pos_deg for s in sweeps],
            [s.backlash_neg_deg for s in sweeps], ours))
    return CatheterProfile(
        "sim-ground-truth", device.device_model,
        datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"), f"tsmd {__version__}", "pchip",
        (knobs[0], knobs[1]), source="ground truth: D/B measured on the simulated tracker's tip")


# ----------------------------------------------------------------------------------------------
# Measurements


@dataclass
class RunResult:
    scenario: Scenario
    method: str
    seed: int
    ptpe_deg: float
    rmse_deg: float
    t_s: NDArray[np.float64]
    q_deg: NDArray[np.float64]
    cmd_deg: NDArray[np.float64]
    tip_deg: NDArray[np.float64]


def run_scenario(s: Scenario, method: str, seed: int, profile: Any,
                 plant_factory: Callable[[], Any], condition: bool = False) -> RunResult:
    tt, qq, skip = conditioned(s.t_s, s.q_deg, condition)
    rec = _run(tt, qq, profile if method != "none" else None, method, seed, plant_factory(),
               not condition)
    tip = np.column_stack([rec["tip1"], rec["tip2"]])[skip:]
    cmd = np.column_stack([rec["cmd1"], rec["cmd2"]])[skip:]
    q = qq[skip:]
    errs = [tracking_errors(tip[:, k], q[:, k]) for k in s.knobs]
    return RunResult(s, method, seed, float(np.mean([e[0] for e in errs])),
                     float(np.mean([e[1] for e in errs])), tt[skip:] - tt[skip], q, cmd, tip)


def compute_time_us(profile: Any, method: str, n_ticks: int = 5000, clock: str = "wall",
                    planned: bool = False) -> tuple[float, float]:
    """Median and p99 time of one ``command`` call for two knobs (microseconds).

    ``clock="wall"``: elapsed time, which on a shared machine includes being preempted;
    ``"cpu"``: this thread's CPU time (the cost of the computation itself), less the clock's
    own cost (the median of empty readings). ``planned``: the tick as the loop runs it while
    playing a trajectory, ``preview`` (where the compensator has it) and ``command`` together.
    """
    read = {"wall": time.perf_counter_ns, "cpu": time.thread_time_ns}[clock]
    comp = build_compensator(profile if method != "none" else None, method, PERIOD_S)
    t = np.arange(n_ticks) * PERIOD_S
    q = np.column_stack([60 * np.sin(2 * math.pi * 0.04 * t), 60 * np.sin(2 * math.pi * 0.08 * t)])
    comp.reset(q[0])
    plan = q.tolist()
    preview = getattr(comp, "preview", None) if planned else None
    times = np.empty(n_ticks)
    empty = np.empty(n_ticks)
    for i, row in enumerate(q):
        t0 = read()
        if preview is not None:
            preview(plan, i)
        comp.command(row, PERIOD_S)
        t1 = read()
        times[i] = t1 - t0
        empty[i] = read() - t1
    times -= float(np.median(empty)) if clock == "cpu" else 0.0
    return float(np.median(times) / 1e3), float(np.percentile(times, 99) / 1e3)


def limiter_cost(profile: Any, method: str, device: Any, scen: Sequence[Scenario]
                 ) -> dict[str, float]:
    """How far the rate/position limiter moves the compensator's command (same trajectories,
    offline): RMS and max deviation and the share of ticks where it acted."""
    dev: list[NDArray[np.float64]] = []
    for s in scen:
        comp = build_compensator(profile, method, PERIOD_S)
        lim = LimitedCompensator(comp, device.limits, PERIOD_S)
        _, qq, _ = settle(s.t_s, s.q_deg, PERIOD_S)
        lim.reset(qq[0])
        for row in qq:
            out = lim.command(row, PERIOD_S)
            dev.append(np.abs(out - lim.last_unlimited))
    d = np.concatenate(dev)
    return {"rms_deg": float(np.sqrt(np.mean(d * d))), "max_deg": float(d.max()),
            "acting_pct": float(100.0 * np.mean(d > 1e-6))}


def command_jerk(r: RunResult) -> tuple[float, float]:
    """(p99, max) of |third difference| of the command, deg/s^3: how abrupt the motion is."""
    j = np.abs(np.diff(r.cmd_deg, n=3, axis=0)[:, list(r.scenario.knobs)]) / PERIOD_S**3
    return float(np.percentile(j, 99)), float(j.max())


# ----------------------------------------------------------------------------------------------
# CLI


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--quick", action="store_true",
                        help="1 seed, 1 cycle, fewer fixed angles (CI smoke test)")
    parser.add_argument("--seeds", type=int, default=None, help="noise seeds (default 5)")
    parser.add_argument("--profile-source", choices=("auto", "calibrate", "ground-truth"),
                        default="auto", help="auto: tsmd calibrate when available, else the "
                        "ground-truth tip (labelled)")
    parser.add_argument("--profile", type=Path, default=None,
                        help="use this profile file instead of calibrating")
    parser.add_argument("--save-profile", type=Path, default=None,
                        help="write the profile the benchmark used here")
    parser.add_argument("--device", type=Path, default=None,
                        help="the product's data sheet (default: capstan's "
                             "profiles/devices/sim-catheter.yaml; with --family the plant's "
                             "shipped sheet)")
    parser.add_argument("--coupling", type=float, default=0.0,
                        help="plant knob-coupling strength (0 = the default simulated catheter)")
    parser.add_argument("--unit-variation", type=float, default=0.0,
                        help="catheter-to-catheter variation of the plant (e.g. 0.1 = +-10 %%); "
                        "0 = the nominal unit the data sheet was measured on")
    parser.add_argument("--unit-seed", type=int, default=1,
                        help="which unit to draw with --unit-variation")
    parser.add_argument("--start", choices=STARTS, default=None,
                        help="the state every run starts from: calibrated (default: a copy of "
                        "the plant as the calibration left it, then one unscored +-90 deg cycle "
                        "of both knobs; without a calibration run here, conditioned), "
                        "conditioned (a fresh plant and the cycle), fresh (no cycle)")
    parser.add_argument("--fresh", action="store_true",
                        help="the same as --start fresh: the fresh plant's tension-free tendons")
    parser.add_argument("--plots", type=Path, default=None,
                        help="directory for the PNG figures (none by default)")
    parser.add_argument("--report", type=Path, default=None,
                        help="write the tables as Markdown to this file")
    family = parser.add_argument_group(
        "the catheter family", "any of these runs `tsmd bench family` instead: each unit "
        "calibrated from its own current, one table per unit and the worst unit")
    family.add_argument("--family", choices=sorted(PLANT_SPECS), default=None,
                        help="score units of this family plant (simrig.family)")
    family.add_argument("--plant", default=None, help="plant factory module:factory")
    family.add_argument("--params", default=None, help="JSON keyword parameters of the plant")
    family.add_argument("--units", default=None,
                        help="with --family: comma-separated unit numbers (101-108 held out)")
    family.add_argument("--unit-seeds", default=None,
                        help="with --plant: comma-separated unit seeds (passed as seed)")
    family.add_argument("--methods", default=None, help="e.g. none,paper,ours")
    family.add_argument("--no-extra", action="store_true", default=None,
                        help="skip the extra scenarios")
    family.add_argument("--profiles", type=Path, default=None,
                        help="keep and reuse each unit's calibrated profile here")


FAMILY_OPTIONS = ("family", "plant", "params", "units", "unit_seeds", "methods", "no_extra",
                  "profiles")
"""Options that make `tsmd bench accuracy` a family run (`tsmd.commands.bench` dispatches)."""


def wants_family(args: argparse.Namespace) -> bool:
    return any(getattr(args, name, None) is not None for name in FAMILY_OPTIONS)


def main(args: argparse.Namespace) -> int:
    quick = bool(args.quick)
    n_seeds = args.seeds if args.seeds is not None else (1 if quick else 5)
    if n_seeds < 1:
        raise TsmdError("--seeds must be at least 1")
    device = load_device_model(args.device if args.device is not None
                               else resolve_data_path("profiles/devices/sim-catheter.yaml"))
    coupling = float(args.coupling)
    unit_variation = float(args.unit_variation)
    if not 0.0 <= unit_variation < 0.5:
        raise TsmdError(f"--unit-variation must be in [0, 0.5), got {unit_variation}")
    unit_seed = int(args.unit_seed)
    if unit_variation > 0:
        print(f"catheter unit: variation +-{unit_variation:.0%}, unit seed {unit_seed} "
              "(data sheet from the nominal unit)")

    def plant_factory() -> Any:
        return make_plant(coupling, unit_variation, unit_seed)

    t_start = time.perf_counter()
    source = args.profile_source
    start = start_of(args)
    calibrated_plant = None
    if args.profile is not None:
        profile = load_profile(args.profile)
        label = f"profile file {args.profile} ({profile.source})"
    else:
        profile = None
        if source in ("auto", "calibrate"):
            try:
                print("calibrating from motor current (tsmd.calibration) ...", flush=True)
                profile, calibrated_plant = calibrate_with_plant(device, plant_factory)
                label = "tsmd calibrate: motor current only"
            except TsmdError as exc:
                if source == "calibrate":
                    raise
                print(f"tsmd calibrate refused this plant ({exc}): using the ground truth")
        if profile is None:
            print("measuring D/B on the simulated tracker's tip (ground truth) ...", flush=True)
            profile = ground_truth_profile(device, plant_factory)
            label = "GROUND TRUTH: D/B measured on the tracked tip, not from motor current"
    if profile is None:  # pragma: no cover - every branch above sets it or raises
        raise TsmdError("no profile")
    if args.save_profile is not None:
        save_profile(profile, args.save_profile)
    print(f"profile: {label}")

    if start == "calibrated" and calibrated_plant is None:
        print("no calibration ran here (profile from a file or the ground truth): "
              "the conditioned start")
        start = "conditioned"
    run_plant = scenario_plant(start, plant_factory, calibrated_plant)
    scen = scenarios(quick)
    results: list[RunResult] = []
    for seed in range(n_seeds):
        for s in scen:
            for method in METHODS:
                results.append(run_scenario(s, method, seed, profile, run_plant,
                                            conditions(start)))
        print(f"seed {seed + 1}/{n_seeds} done ({time.perf_counter() - t_start:.0f} s)",
              flush=True)

    groups = summarise(results, lambda r: r.scenario.group)
    fixed = summarise([r for r in results if r.scenario.group == "1-DOF periodic"],
                      lambda r: "other knob at " + ("0" if r.scenario.name.endswith("+0") else
                                                     "±" + r.scenario.name.split()[-1][1:]))
    lines = [f"Profile: {label}", f"Seeds: {n_seeds}; quick: {quick}; plant coupling: {coupling}"
             f"; start: {start} ({start_label(start)})",
             "", "Tip against desired, degrees (mean ± std over seeds):", ""]
    lines += format_table(groups, with_paper=True)
    lines += ["", "1-DOF periodic by the other knob's fixed angle (paper's Table 1d_fixed):", ""]
    lines += format_table(fixed, with_paper=False)
    lines += ["", "Per-tick compute time of the compensator for two knobs (this machine; wall "
              "includes preemption, CPU is this thread's):", "",
              "| method | wall median µs | wall p99 µs | CPU median µs | CPU p99 µs |",
              "|---|---|---|---|---|"]
    for method in METHODS:
        med, p99 = compute_time_us(profile, method)
        cpu_med, cpu_p99 = compute_time_us(profile, method, clock="cpu")
        lines.append(f"| {method} | {med:.1f} | {p99:.1f} | {cpu_med:.1f} | {cpu_p99:.1f} |")
    med, p99 = compute_time_us(profile, "ours", planned=True)
    cpu_med, cpu_p99 = compute_time_us(profile, "ours", clock="cpu", planned=True)
    lines.append(f"| ours, playing a trajectory (preview + command) | {med:.1f} | {p99:.1f} | "
                 f"{cpu_med:.1f} | {cpu_p99:.1f} |")
    lines += ["", "Rate/position limiter (device limits) on the compensators' commands, "
              "same trajectories offline:", "",
              "| method | RMS deviation deg | max deviation deg | ticks limited |",
              "|---|---|---|---|"]
    for method in ("paper", "ours"):
        c = limiter_cost(profile, method, device, scen)
        lines.append(f"| {method} | {c['rms_deg']:.3f} | {c['max_deg']:.2f} | "
                     f"{c['acting_pct']:.1f} % |")
    lines += ["", "Command jerk p99 / max (deg/s^3, seed 0, as run):", "",
              "| scenario | none | paper | ours |", "|---|---|---|---|"]
    for s in scen:
        row = [command_jerk(r) for m in METHODS for r in results
               if r.scenario is s and r.method == m and r.seed == 0]
        lines.append(f"| {s.group}, {s.name} | "
                     + " | ".join(f"{p99:.3g} / {top:.3g}" for p99, top in row) + " |")
    lines += ["", f"Wall time: {time.perf_counter() - t_start:.0f} s"]
    print("\n".join(lines))

    if args.plots is not None:
        for group, name, fname in (
                ("1-DOF periodic", "phi1, other at +0", "accuracy-1dof-periodic.png"),
                ("1-DOF non-periodic", "phi1, other at +0", "accuracy-1dof-nonperiodic.png"),
                ("2-DOF periodic", None, "accuracy-2dof-periodic.png"),
                ("2-DOF non-periodic", None, "accuracy-2dof-nonperiodic.png")):
            runs = [r for r in results if r.seed == 0 and r.scenario.group == group
                    and (name is None or r.scenario.name == name)]
            if runs:
                plot_runs(runs, args.plots / fname, f"{group}: {runs[0].scenario.name}")
        print(f"figures in {args.plots}")
    if args.report is not None:
        args.report.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return 0
