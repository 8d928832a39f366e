"""`tsmd bench family`: tracking accuracy on a family of catheter units, each calibrated from its
own motor current, scored against the simulated tip.

Each unit is drawn from a plant factory (``module:factory`` with JSON parameters; by default the
built-in capstan plant with ``unit_variation`` and a unit ``seed``), calibrated by
``tsmd.calibration.calibrate`` through the full simulated stack, then every scenario runs through
the full stack (``tsmd.bench.accuracy.run_scenario``) for each method. The data sheet stays the
one measured once on the nominal unit, which is therefore not scored. Printed: per unit and
scenario the RMSE/PTPE of each method, the reductions against no compensation, the ratio of
ours' RMSE to the paper's, and the worst unit and scenario.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.family import PLANT_ROLE, PLANT_SPECS, family_member
from simrig.plant import PlantLoadError, load_plant
from tsmd.bench.accuracy import compute_time_us, run_scenario
from tsmd.bench.accuracy_report import plot_runs
from tsmd.bench.error_split import split_run
from tsmd.bench.tracking_start import (
    STARTS,
    cached_unit,
    conditions,
    scenario_plant,
    start_label,
    start_of,
)
from tsmd.calibration.errors import CalibrationError
from tsmd.config import resolve_data_path
from tsmd.errors import TsmdError
from tsmd.profile import CatheterProfile, load_device_model
from tsmd.tracking_scenarios import PERIOD_S, Scenario, scenarios

FloatArray = NDArray[np.float64]
DEFAULT_PLANT = "simrig.plants.capstan.tendon_sheath:make_tendon_sheath_plant"
TARGET_RMSE_PCT = {"1-DOF": 90.0, "2-DOF": 85.0}
TARGET_PTPE_PCT = {"1-DOF": 75.0, "2-DOF": 60.0}
TARGET_RATIO_TO_PAPER = 0.6


def extra_scenarios() -> list[Scenario]:
    """Beyond the paper: 0.1 Hz triangles, point-to-point moves with dwell, a multisine."""
    out: list[Scenario] = []
    t = np.arange(0.0, 20.0, PERIOD_S)
    phase = (0.1 * t) % 1.0
    tri = 60.0 * np.where(phase < 0.25, 4 * phase, np.where(phase < 0.75, 2 - 4 * phase,
                                                            4 * phase - 4))
    q = np.zeros((t.size, 2))
    q[:, 0] = tri
    out.append(Scenario("1-DOF triangle", "phi1 0.1 Hz +-60", t, q, (0,)))
    targets = (40.0, -20.0, 60.0, 10.0, -50.0, 25.0, -5.0, 0.0)
    t_p = np.arange(0.0, 4.0 * len(targets), PERIOD_S)
    q_p = np.zeros((t_p.size, 2))
    start = 0.0
    for k, goal in enumerate(targets):  # 1.5 s raised-cosine move, 2.5 s dwell
        sel = (t_p >= 4.0 * k) & (t_p < 4.0 * (k + 1))
        s = np.clip((t_p[sel] - 4.0 * k) / 1.5, 0.0, 1.0)
        q_p[sel, 1] = start + (goal - start) * (0.5 - 0.5 * np.cos(math.pi * s))
        start = goal
    out.append(Scenario("1-DOF point-to-point", "phi2 moves with 2.5 s dwell", t_p, q_p, (1,)))
    t_m = np.arange(0.0, 50.0, PERIOD_S)
    freqs = (0.02, 0.05, 0.11, 0.17)
    amps = (30.0, 15.0, 8.0, 4.0)
    phases = (0.0, 1.3, 2.9, 4.1)
    multi = np.zeros_like(t_m)
    for a, f, p in zip(amps, freqs, phases, strict=True):  # starts at 0
        multi += a * (np.sin(2 * math.pi * f * t_m + p) - math.sin(p))
    q_m = np.column_stack([multi, 0.8 * multi[::-1] - 0.8 * multi[-1]])
    out.append(Scenario("2-DOF multisine", "4 tones 0.02-0.17 Hz", t_m, q_m, (0, 1)))
    return out


def plant_factory(spec: str, params: dict[str, Any]) -> Callable[[], Any]:
    def make() -> Any:
        try:
            return load_plant(spec, params)
        except PlantLoadError as exc:
            raise TsmdError(str(exc)) from None

    make()  # fail early with a one-line error
    return make


def _pct(none: float, other: float) -> float:
    return 100.0 * (none - other) / none if none > 0 else math.nan  # NaN > 0 is False


def unit_profile(unit: int, device: Any, make: Callable[[], Any], directory: Path | None,
                 need_plant: bool = False) -> tuple[CatheterProfile, Any]:
    """The unit's profile from ``tsmd calibrate`` (motor current), kept in ``directory``, and
    with ``need_plant`` the plant its calibration left (:mod:`tsmd.bench.tracking_start`)."""
    path = None if directory is None else directory / f"unit-{unit}.yaml"
    return cached_unit(path, device, make, need_plant,
                       lambda text: print(f"unit {unit}: {text}", flush=True))


def sheet_path(family: str | None, device: Path | None) -> Path:
    """The data sheet a run uses: the one asked for, else the family plant's shipped sheet.

    The shipped sheets are what `tsmd datasheet` measured on each plant's unit 0, every
    per-product field included (rule, reading offset, templates); a sheet measured here from
    the slope and reference points alone would silently drop them.
    """
    if device is not None:
        return device
    if family is None or family == "capstan":
        return resolve_data_path("profiles/devices/sim-catheter.yaml")
    return resolve_data_path(f"profiles/devices/family/{family}.yaml")


def namespace_from(args: argparse.Namespace) -> argparse.Namespace:
    """This bench's options from another bench's (``tsmd bench accuracy --family ...``): its own
    defaults, overridden by every option ``args`` sets to something other than None."""
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    out = parser.parse_args([])
    for name in vars(out):
        value = getattr(args, name, None)
        if value is not None:
            setattr(out, name, value)
    return out


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--family", choices=sorted(PLANT_SPECS), default=None,
                        help="score units of a family plant (simrig.family) instead of --plant; "
                             "the data sheet is --device, by default the plant's shipped one "
                             "(profiles/devices/family/<plant>.yaml, measured on its unit 0)")
    parser.add_argument("--units", default="101,102",
                        help="with --family: comma-separated unit numbers (1-8 development, "
                             "101-108 held out)")
    parser.add_argument("--plant", default=DEFAULT_PLANT, help="plant factory module:factory")
    parser.add_argument("--params", default="{}", help="JSON keyword parameters of the plant")
    parser.add_argument("--unit-variation", type=float, default=0.15,
                        help="unit scatter passed to the plant as unit_variation (0: not passed)")
    parser.add_argument("--unit-seeds", default="1,2,3",
                        help="comma-separated unit seeds (passed as seed)")
    parser.add_argument("--methods", default="none,paper,ours")
    parser.add_argument("--quick", action="store_true", help="the paper's quick scenario set")
    parser.add_argument("--no-extra", action="store_true", help="skip the extra scenarios")
    parser.add_argument("--start", choices=STARTS, default=None,
                        help="the state each scenario starts from: calibrated (default: a copy "
                             "of the plant as the unit's calibration left it, warm and soaked, "
                             "then one unscored +-90 deg cycle), conditioned (a fresh plant and "
                             "the cycle, the default until session 27), fresh (no cycle)")
    parser.add_argument("--fresh", action="store_true", help="the same as --start fresh")
    parser.add_argument("--device", type=Path, default=None,
                        help="the product's data sheet (default: with --family the plant's "
                             "shipped sheet, else capstan's profiles/devices/sim-catheter.yaml)")
    parser.add_argument("--report", type=Path, default=None)
    parser.add_argument("--profiles", type=Path, default=None,
                        help="keep each unit's calibrated profile here as unit-<n>.yaml and "
                             "reuse it when present (scoring again without recalibrating)")
    parser.add_argument("--plots", type=Path, default=None,
                        help="directory for time and input-output figures of the first unit")
    parser.add_argument("--split", action="store_true",
                        help="after each row, ours' error per knob split by the branch its "
                             "model is on (loaded, release, plateau, backlash; tip: diagnosis)")


def main(args: argparse.Namespace) -> int:
    try:
        base = json.loads(args.params)
    except json.JSONDecodeError as exc:
        raise TsmdError(f"--params is not valid JSON: {exc}") from None
    if not isinstance(base, dict):
        raise TsmdError("--params must be a JSON object")
    try:
        seeds = [int(s) for s in str(args.unit_seeds).split(",") if s.strip()]
    except ValueError:
        raise TsmdError(f"--unit-seeds must be integers, got {args.unit_seeds!r}") from None
    methods = [m.strip() for m in str(args.methods).split(",") if m.strip()]
    sheet = sheet_path(args.family, args.device)
    device = load_device_model(sheet)
    scen = scenarios(bool(args.quick)) + ([] if args.no_extra else extra_scenarios())
    start = start_of(args)
    t0 = time.perf_counter()
    lines = [f"plant {args.plant} {json.dumps(base)}; unit_variation {args.unit_variation}; "
             f"units {seeds}; start {start} ({start_label(start)})", "",
             "| unit | scenario | " + " | ".join(f"{m} RMSE/PTPE" for m in methods)
             + " | RMSE red. % | PTPE red. % | RMSE / paper |", "|" + "---|" * (len(methods) + 5)]
    rows: list[tuple[int, str, str, float, float, float]] = []
    units: list[tuple[int, Callable[[], Any]]] = []
    if args.family is not None:
        try:
            numbers = [int(u) for u in str(args.units).split(",") if u.strip()]
            members = [family_member(args.family, u) for u in numbers]
        except (ValueError, PlantLoadError) as exc:
            raise TsmdError(f"--units: {exc}") from None
        lines[0] = (f"family plant {args.family} ({PLANT_ROLE[args.family]}); units {numbers}; "
                    f"data sheet {sheet} ({device.device_model}); "
                    f"start {start} ({start_label(start)})")
        units = [(m.unit, m.build) for m in members]
    for seed in seeds if args.family is None else []:
        params = dict(base)
        if args.unit_variation > 0:
            params.update(unit_variation=float(args.unit_variation), seed=seed)
        units.append((seed, plant_factory(args.plant, params)))
    refused: list[int] = []
    for seed, make in units:
        try:
            profile, plant = unit_profile(seed, device, make, args.profiles,
                                          start == "calibrated")
        except CalibrationError as exc:  # a finding about the unit: score the others
            refused.append(seed)
            line = f"| {seed} | no profile: {exc} |"
            lines.append(line)
            print(line, flush=True)
            continue
        run_plant = scenario_plant(start, make, plant)
        for s in scen:
            res = {m: run_scenario(s, m, 0, profile, run_plant, conditions(start))
                   for m in methods}
            red, red_p, ratio = _figures(res)
            rows.append((seed, s.group, s.name, red, red_p, ratio))
            line = (f"| {seed} | {s.group}: {s.name} | "
                    + " | ".join(f"{res[m].rmse_deg:.2f}/{res[m].ptpe_deg:.1f}" for m in methods)
                    + f" | {red:.1f} | {red_p:.1f} | {ratio:.2f} |")
            lines.append(line)
            print(line, f"({time.perf_counter() - t0:.0f} s)", flush=True)
            if args.split and "ours" in res:
                lines += _split_lines(seed, res["ours"], profile)
            if args.plots is not None and seed == units[0][0]:
                runs = list(res.values())
                name = f"family-unit{seed}-{s.group}-{s.name}".replace(" ", "_")
                plot_runs(runs, args.plots / (re.sub(r"[^A-Za-z0-9_.-]", "", name) + ".png"),
                          f"unit {seed}: {s.group}, {s.name}")
        med, p99 = compute_time_us(profile, "ours")
        cpu_med, cpu_p99 = compute_time_us(profile, "ours", clock="cpu")
        lines.append(f"| {seed} | compute per tick, two knobs (ours) | wall median {med:.1f} us, "
                     f"p99 {p99:.1f} us; CPU median {cpu_med:.1f} us, p99 {cpu_p99:.1f} us |")
        med, p99 = compute_time_us(profile, "ours", planned=True)
        cpu_med, cpu_p99 = compute_time_us(profile, "ours", clock="cpu", planned=True)
        lines.append(f"| {seed} | the same playing a trajectory (preview + command) | wall median "
                     f"{med:.1f} us, p99 {p99:.1f} us; CPU median {cpu_med:.1f} us, "
                     f"p99 {cpu_p99:.1f} us |")
    lines += ["", "Targets (ours): RMSE red. >= 90 % 1-DOF / 85 % 2-DOF, PTPE red. >= 75 "
              "/ 60 %, RMSE <= 0.6 x paper's.", ""]
    if refused:
        lines.append(f"no profile (calibration refused or failed) for {len(refused)} of "
                     f"{len(units)} units: {refused}")
    if not rows:
        return _emit([*lines, "no unit was scored"], args.report, 1)
    for label, idx in (("RMSE reduction", 3), ("PTPE reduction", 4)):
        worst = min(rows, key=lambda r: r[idx])
        lines.append(f"worst {label}: {worst[idx]:.1f} % (unit {worst[0]}, {worst[1]}: "
                     f"{worst[2]})")
    worst_ratio = max(rows, key=lambda r: r[5])
    lines.append(f"worst RMSE ratio to paper: {worst_ratio[5]:.2f} (unit {worst_ratio[0]}, "
                 f"{worst_ratio[1]}: {worst_ratio[2]})")
    misses = [r for r in rows if r[3] < TARGET_RMSE_PCT[r[1].split()[0]]
              or r[4] < TARGET_PTPE_PCT[r[1].split()[0]] or r[5] > TARGET_RATIO_TO_PAPER]
    lines.append(f"rows missing a target: {len(misses)} of {len(rows)}")
    lines.append(f"wall time {time.perf_counter() - t0:.0f} s")
    return _emit(lines, args.report, 0)


def _figures(res: dict[str, Any]) -> tuple[float, float, float]:
    """Ours' RMSE and PTPE reductions against no compensation and its RMSE over the paper's;
    NaN where a method was not run (``--methods paper,ours`` compares the two alone)."""
    def get(method: str, name: str) -> float:
        return float(getattr(res[method], name)) if method in res else math.nan

    return (_pct(get("none", "rmse_deg"), get("ours", "rmse_deg")),
            _pct(get("none", "ptpe_deg"), get("ours", "ptpe_deg")),
            get("ours", "rmse_deg") / get("paper", "rmse_deg"))


def _split_lines(unit: int, run: Any, profile: CatheterProfile) -> list[str]:
    """Report lines of ours' error split by the model's branch (:mod:`tsmd.bench.error_split`)."""
    params = [k.tension_play for k in profile.knobs if k.tension_play is not None]
    if len(params) != 2:
        return []
    splits = split_run(run.q_deg, run.cmd_deg, run.tip_deg, params, run.scenario.knobs, PERIOD_S)
    out = [f"| {unit} | split of ours' error, {s.line()} |" for s in splits]
    print("\n".join(out), flush=True)
    return out


def _emit(lines: list[str], report: Path | None, status: int) -> int:
    """Print the table and its summary, and write them to ``report`` if given."""
    print("\n".join(lines))
    if report is not None:
        report.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return status


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__)
    add_arguments(parser)
    raise SystemExit(main(parser.parse_args()))
