"""`tsmd bench calibration`: the calibration on a family of simulated catheters, and on the
real TEE acquisitions.

Simulator (:mod:`tsmd.bench.calibration_family`): each catheter of a plant family (``--plant
module:factory --params JSON``, one unit per seed ``--unit-key``) with several noise seeds runs
the paper protocol and the fast one through the full stack in lockstep; the calibration sees
only commanded/actual position and current. The truth per grid point is measured on the
simulated EM tracker's tip angle by the plant package's own analysis (``simrig.analysis``:
the dead-zone edge where the tip has moved 1 deg past its rest on that side, the backlash as
the knob travel from a reversal until the tip has moved 1 deg), never read from the plant's
parameters; the tracker signal is low-passed with the same 20 Hz zero-phase Butterworth first.
Injected faults (``--unhealthy``) must all be refused with their reason.

Real TEE acquisitions: D and B from the current (with their uncertainty) against D and B read
off the tracked tip, per pass, reported as they are.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import sys
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

from simrig.analysis import _rising_pass_measures
from tsmd.bench.calibration_family import family_table, run_catheter_summary
from tsmd.bench.calibration_faults import fault_table
from tsmd.bench.calibration_time import main_time
from tsmd.calibration.assemble import GridPoint
from tsmd.calibration.errors import CalibrationError
from tsmd.calibration.identify import IdentifyOptions, split_half_cycles
from tsmd.calibration.offline import SHORT
from tsmd.calibration.run import identify_recording
from tsmd.calibration.sweep_result import PARAMETERS
from tsmd.config import resolve_data_path
from tsmd.errors import TsmdError
from tsmd.profile import load_device_model
from tsmd.tee import DEFAULT_STEPS_PER_KNOB_DEG, default_tee_dir, load_tee_acquisition
from tsmd.tip_truth import TIP_THRESHOLD_DEG

DEFAULT_PLANT = "simrig.plants.capstan:make_tendon_sheath_plant"
DEFAULT_DEVICE = "profiles/devices/sim-catheter.yaml"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--plant", default=DEFAULT_PLANT, metavar="MODULE:FACTORY",
                        help=f"plant factory of the family (default {DEFAULT_PLANT})")
    parser.add_argument("--params", default='{"unit_variation": 0.15}', metavar="JSON",
                        help="the factory's keyword parameters shared by every unit")
    parser.add_argument("--unit-key", default="seed",
                        help="the factory's parameter that names one catheter (default seed)")
    parser.add_argument("--units", type=int, default=20, help="how many catheters")
    parser.add_argument("--first-unit", type=int, default=100,
                        help="first unit seed (default 100: units 0-9 were used to develop)")
    parser.add_argument("--noise-seeds", default="0", metavar="LIST",
                        help="comma-separated noise seeds per catheter (default 0)")
    parser.add_argument("--protocol", choices=("paper", "fast", "both"), default=None,
                        help="default: both (--time: paper, the target's protocol)")
    parser.add_argument("--device", metavar="FILE", default=DEFAULT_DEVICE,
                        help="device model (data sheet) used by the calibration")
    parser.add_argument("--jobs", type=int, default=1, help="catheters run in parallel")
    parser.add_argument("--unhealthy", action="store_true",
                        help="also inject faults on the first unit; each must be refused")
    parser.add_argument("--no-sim", action="store_true", help="skip the simulator part")
    parser.add_argument("--no-tee", action="store_true", help="skip the real TEE data")
    parser.add_argument("--tee-dir", metavar="DIR",
                        help="TEE data directory (default: $TSMD_TEE_DATA or ../shared/data/tee)")
    parser.add_argument("--time", action="store_true",
                        help="only time one calibration as `tsmd calibrate --sim` runs it (sim "
                             "config's plant, --protocol paper (default) or fast, noise seed = "
                             "first of --noise-seeds): wall, CPU, peak RSS, where a tick goes")
    parser.add_argument("--plant-step-us", type=float, default=0.0, metavar="US",
                        help="--time: every plant step lasts at least this long (busy wait)")
    parser.add_argument("--pace-cpu", action="store_true",
                        help="--time: pace the plant on CPU time (the run's CPU is then what an "
                             "idle core would take, whatever the load)")
    parser.add_argument("--split-ticks", type=int, default=12500, metavar="N",
                        help="--time: ticks of the per-layer split (default 12500: one sweep)")


def main(args: argparse.Namespace) -> int:
    if args.time:
        if args.protocol == "both" or args.split_ticks < 1 or not args.plant_step_us >= 0:
            raise TsmdError("--time needs --protocol paper or fast, --split-ticks >= 1 and "
                            "--plant-step-us >= 0")
        seed = int(str(args.noise_seeds).split(",")[0])
        device = load_device_model(resolve_data_path(args.device))
        print("\n".join(main_time(device, fast=args.protocol == "fast",
                                   plant_step_us=args.plant_step_us,
                                   split_n=args.split_ticks, seed=seed,
                                   pace_cpu=args.pace_cpu)))
        return 0
    if not args.no_sim:
        print(family(args))
    if not args.no_tee:
        print("\n## Real TEE acquisitions\n")
        print(tee_table(args.tee_dir))
    return 0


def family(args: argparse.Namespace) -> str:
    """Every catheter and noise seed, one table per protocol, the worst unit; faults."""

    try:
        params = json.loads(args.params)
        seeds = [int(s) for s in str(args.noise_seeds).split(",") if s.strip()]
    except ValueError as exc:
        raise TsmdError(f"--params must be a JSON object and --noise-seeds integers: {exc}"
                        ) from None
    if not isinstance(params, dict):
        raise TsmdError("--params must be a JSON object")
    device = load_device_model(resolve_data_path(args.device))
    protocols = ("paper", "fast") if args.protocol in (None, "both") else (args.protocol,)
    tasks = [(args.plant, params, args.unit_key, u, s, device, protocols)
             for u in range(args.first_unit, args.first_unit + args.units) for s in seeds]
    t0 = time.monotonic()
    results = []
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = [pool.submit(run_catheter_summary, *t) for t in tasks]
        for future in as_completed(futures):
            results.append(future.result())
            c = results[-1]
            # One line per catheter as it ends (a long family run shows where it is).
            print(f"unit {c.unit} seed {c.noise_seed}: " + "; ".join(
                f"{name} {'accepted' if r.accepted else 'REFUSED'}, {r.within}/"
                f"{len(r.errors)} within 2 deg, max {r.max_error:.2f}, {len(r.resweeps)} "
                f"re-sweeps, {r.wall_s:.0f} s, u95 covers " + ", ".join(
                    f"{kind} {x}/{n}" for kind, (x, n) in r.coverage.items())
                for name, r in c.runs.items()),
                file=sys.stderr, flush=True)
    results.sort(key=lambda c: (c.unit, c.noise_seed))
    wall = time.monotonic() - t0
    out = [f"## Plant {args.plant} {json.dumps(params)}: units {args.first_unit}-"
           f"{args.first_unit + args.units - 1} ({args.unit_key}), noise seeds "
           f"{', '.join(map(str, seeds))}", ""]
    for name in protocols:
        out += [f"### {name} protocol", "", family_table(results, name), ""]
    rss = max((r.peak_rss_MiB for r in results), default=math.nan)
    out.append(f"- {len(results)} runs in {wall:.0f} s wall with {args.jobs} jobs; peak RSS of "
               f"one run {rss:.0f} MiB (this process {_rss_MiB():.0f} MiB); load average "
               f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs")
    if args.unhealthy:

        out += ["", f"### Injected faults (unit {args.first_unit}, noise seed {seeds[0]})",
                "", fault_table(args.plant, params, args.unit_key, args.first_unit, seeds[0],
                                device)]
    return "\n".join(out)


def _rss_MiB() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


# --- real TEE data ------------------------------------------------------------------------


def tee_tip_measures(point: GridPoint) -> dict[str, list[float]]:
    """Per pass on the tracked tip, with the plant analysis' threshold definitions."""

    rec = point.recording
    assert rec is not None
    k = point.knob + 1
    q, tip = rec[f"pos{k}"], rec[f"tip{k}"]
    out: dict[str, list[float]] = {p: [] for p in PARAMETERS}
    for direction, a, b, after_reversal in split_half_cycles(rec[f"cmd{k}"], 10.0):
        ends_mid_pass = b >= len(q)  # no reversal at the end: the edge may not be reached
        qs, ts = direction * q[a:b], direction * tip[a:b]
        backlash, edge = _rising_pass_measures(qs, ts, TIP_THRESHOLD_DEG)
        b_name = "backlash_neg_deg" if direction > 0 else "backlash_pos_deg"
        d_name = "dead_zone_pos_deg" if direction > 0 else "dead_zone_neg_deg"
        if after_reversal and math.isfinite(backlash):
            out[b_name].append(backlash)
        if math.isfinite(edge) and not ends_mid_pass:
            out[d_name].append(direction * edge)
    return out


def tee_table(directory: str | None) -> str:

    root = Path(directory) if directory else default_tee_dir()
    files = sorted(root.glob("motor*_current60__*.csv")) if root.is_dir() else []
    if not files:
        return f"(no TEE data in {root}: skipped)"
    head = ["acquisition", "knob", *(f"{SHORT[p]} current / tip" for p in PARAMETERS), "SNR"]
    lines = [f"Assumed {DEFAULT_STEPS_PER_KNOB_DEG:g} motor steps per knob degree and 50 Hz "
             "sampling (tsmd/tee.py). '-' = not found (reason in the report).", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for f in files:
        rec = load_tee_acquisition(f)
        try:
            point = identify_recording(rec, source=f.name)
        except CalibrationError as exc:
            lines.append(f"| {f.stem} | - | {exc} |")
            continue
        tip = tee_tip_measures(point)
        rise = identify_recording(rec, IdentifyOptions(edge="rise"), source=f.name)
        cells = [f.stem.replace("_current60__", " "), f"phi{point.knob + 1}"]
        for p in PARAMETERS:
            cur = _fmt(point.result.values.get(p, ()))
            if p.startswith("dead_zone"):
                cur += f" (paper's rise {_fmt(rise.result.values.get(p, ()))})"
            cells.append(f"{cur} / {_fmt(tuple(tip[p]))}")
        snr = point.result.snr
        cells.append(f"{snr:.1f}" if math.isfinite(snr) else "-")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def _fmt(values: Sequence[float]) -> str:
    return ", ".join(f"{v:.1f}" for v in values) if values else "-"
