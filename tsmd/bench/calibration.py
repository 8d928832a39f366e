"""`tsmd bench calibration`: identified D and B against the truth read off the tip.

On the simulator: both protocols (the paper's and the fast one) run through the full stack in
lockstep (drivers + loop, E's ``LockstepRunner``); the calibration sees only commanded/actual
position and current. The truth per grid point is measured on the simulated EM tracker's tip
angle by the plant package's own analysis (``simrig.analysis``), never read from the
plant's parameters. The tracker signal is low-passed with the same 20 Hz zero-phase Butterworth
first (its 0.2 deg noise would otherwise cross the 1 deg threshold by itself).

On the real TEE acquisitions: D and B from the current against D and B read off the tracked tip
(same threshold definitions, per pass: the files hold one slow cycle each), reported as they are.
"""

from __future__ import annotations

import argparse
import math
import os
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from scipy.interpolate import PchipInterpolator

from simrig.analysis import SweepAnalysisError, _rising_pass_measures, measure_dead_zone_backlash
from tsmd.calibration import fast_protocol, paper_protocol
from tsmd.calibration.assemble import KNOB_LABELS, GridPoint
from tsmd.calibration.errors import CalibrationError
from tsmd.calibration.identify import PARAMETERS, IdentifyOptions, split_half_cycles
from tsmd.calibration.offline import SHORT
from tsmd.calibration.run import finish, identify_recording, run_sweeps
from tsmd.calibration.signal import lowpass
from tsmd.config import default_sim_config, load_config, resolve_data_path
from tsmd.profile import load_device_model
from tsmd.replay import LockstepRunner
from tsmd.tee import DEFAULT_STEPS_PER_KNOB_DEG, default_tee_dir, load_tee_acquisition

TARGET_DEG = 2.0
TIP_THRESHOLD_DEG = 1.0


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--protocol", choices=("paper", "fast", "both"), default="both")
    parser.add_argument("--seed", type=int, default=0, help="simulator noise seed")
    parser.add_argument("--config", metavar="FILE", help="tsmd config (default: the sim one)")
    parser.add_argument("--no-sim", action="store_true", help="skip the simulator part")
    parser.add_argument("--no-tee", action="store_true", help="skip the real TEE data")
    parser.add_argument("--tee-dir", metavar="DIR",
                        help="TEE data directory (default: $TSMD_TEE_DATA or ../shared/data/tee)")


def main(args: argparse.Namespace) -> int:
    if not args.no_sim:
        protocols = ("paper", "fast") if args.protocol == "both" else (args.protocol,)
        results = {name: sim_protocol(name, args.seed, args.config) for name in protocols}
        for name, res in results.items():
            print(f"\n## Simulator, {name} protocol (seed {args.seed})\n")
            print(res["summary"])
            print()
            print(res["table"])
        if len(results) == 2:
            print("\n" + compare_protocols(results["paper"]["points"],
                                           results["fast"]["points"]))
    if not args.no_tee:
        print("\n## Real TEE acquisitions\n")
        print(tee_table(args.tee_dir))
    return 0


# --- simulator ----------------------------------------------------------------------------


def tip_truth(point: GridPoint) -> dict[str, float]:
    """D and B measured on the tracked tip of the sweep (the plant package's analysis)."""
    rec = point.recording
    if rec is None:
        return {}
    k = point.knob + 1
    start = float(rec.metadata["calibration_sweep_start_s"]) - 1.0  # include the way down to -A
    m = rec["t"] >= start
    t, pos, tip = rec["t"][m], rec[f"pos{k}"][m], rec[f"tip{k}"][m]
    if not np.isfinite(tip).all():
        return {}
    rate = 1.0 / float(np.median(np.diff(t)))
    tip_f, _ = lowpass(tip, rate)
    knob = monotone_knob(rec[f"cmd{k}"][m], pos)
    try:
        truth = measure_dead_zone_backlash(knob, tip_f, threshold_deg=TIP_THRESHOLD_DEG)
    except SweepAnalysisError:
        return {}
    return dict(truth._asdict())


def monotone_knob(cmd_deg: np.ndarray, pos_deg: np.ndarray) -> np.ndarray:
    """The actual knob angle made monotonic between the command's reversals.

    At a speed change the drive's position wobbles back by ~0.02 deg; the plant analysis cuts
    passes at every direction change, so without this a wobble becomes a "reversal" and the
    tip's backlash comes out as the 1 deg threshold's knob travel.
    """
    out = np.asarray(pos_deg, dtype=float).copy()
    for direction, a, b, _ in split_half_cycles(np.asarray(cmd_deg, dtype=float), 10.0):
        out[a:b] = direction * np.maximum.accumulate(direction * out[a:b])
    return out


def sim_protocol(name: str, seed: int, config_path: str | None) -> dict[str, Any]:
    config = load_config(config_path) if config_path else default_sim_config()
    proto = paper_protocol() if name == "paper" else fast_protocol()
    t0, cpu0 = time.monotonic(), time.process_time()
    with LockstepRunner(config, seed=seed) as runner:
        runs = run_sweeps(runner, proto)
    wall, cpu = time.monotonic() - t0, time.process_time() - cpu0
    verdict = "profile accepted by the quality checks"
    device_path = config.profiles.device_model or "profiles/devices/sim-catheter.yaml"
    try:
        device = load_device_model(resolve_data_path(device_path))
        _, quality = finish("bench", device, runs.points, amplitude_deg=90.0)
        verdict += "".join(f"; warning: {w}" for w in quality.warnings)
    except CalibrationError as exc:
        verdict = f"profile REFUSED by the quality checks: {exc}"
    # The calibration itself used the default (knee) edge; the paper's own edge for comparison.
    rise = {(p.knob, p.other_deg): identify_recording(p.recording, IdentifyOptions(edge="rise"))
            for p in runs.points if p.recording is not None}
    rows = []
    errors: dict[str, list[float]] = {"paper": [], "knee": []}
    single: dict[str, list[float]] = {"B": [], "D knee": [], "D paper": []}
    cycle_gaps: dict[str, list[float]] = {"B": [], "D knee": [], "D paper": []}
    for p in sorted(runs.points, key=lambda q: (q.knob, q.other_deg)):
        truth = tip_truth(p)
        r_result = rise[(p.knob, p.other_deg)].result
        for kind, result, names in (("B", p.result, PARAMETERS[2:]),
                                    ("D paper", r_result, PARAMETERS[:2]),
                                    ("D knee", p.result, PARAMETERS[:2])):
            for name in names:
                values = result.values.get(name, ())
                # Signed outward: a dead-zone edge inside the tip's counts negative on both sides.
                sign = -1.0 if name == "dead_zone_neg_deg" else 1.0
                single[kind] += [sign * (v - truth.get(name, math.nan)) for v in values]
                if len(values) > 1:
                    cycle_gaps[kind].append(float(np.ptp(values)))
        cells = [KNOB_LABELS[p.knob], f"{p.other_deg:+.0f}"]
        for param in PARAMETERS:
            true = truth.get(param, math.nan)
            ident = p.result.estimate(param)
            if param.startswith("dead_zone"):
                r_ident = r_result.estimate(param)
                errors["paper"].append(r_ident - true)
                errors["knee"].append(ident - true)
                text = f"{r_ident:.1f} / {ident:.1f}"
            else:
                errors["paper"].append(ident - true)
                errors["knee"].append(ident - true)
                text = f"{ident:.1f}"
            cells.append(f"{text} / {true:.1f}")
        rows.append(cells)
    head = ["knob", "other (deg)", "D_pos paper / knee / tip", "D_neg paper / knee / tip",
            "B_pos current / tip", "B_neg current / tip"]
    table = "\n".join(["| " + " | ".join(head) + " |", "|" + "---|" * len(head),
                       *("| " + " | ".join(r) + " |" for r in rows)])
    summary = (f"- sweeping {proto.sweep_time_s:.0f} s, motion {runs.motion_time_s:.0f} s "
               f"(simulated), wall {wall:.1f} s, CPU {cpu:.1f} s of this process "
               f"(load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs)\n"
               f"- {verdict}\n" + _error_summary(errors["paper"], "with the paper's edge (rise)")
               + _error_summary(errors["knee"], "tsmd calibrate (knee edge, the default)")
               + _scatter_summary(single, cycle_gaps))
    return {"points": runs.points, "table": table, "summary": summary, "wall_s": wall,
            "errors": errors}


def _error_summary(signed: list[float], label: str) -> str:
    """Per parameter kind: max |error|, and how many of all values are within the target."""
    errs = np.abs(np.asarray(signed, dtype=float)).reshape(-1, len(PARAMETERS))
    parts = []
    for j, param in enumerate(PARAMETERS):
        col = errs[:, j][np.isfinite(errs[:, j])]
        parts.append(f"{SHORT[param]} max {col.max() if col.size else math.nan:.1f}")
    finite = errs[np.isfinite(errs)]
    within = int((finite <= TARGET_DEG).sum())
    return (f"- {label}: |error| {', '.join(parts)} deg; within {TARGET_DEG:g} deg: {within} "
            f"of {errs.size} values ({errs.size - finite.size} without a tip value)\n")


def _scatter_summary(single: dict[str, list[float]], gaps: dict[str, list[float]]) -> str:
    """How one half-cycle's value scatters around the tip's, and how far two cycles differ:
    what the quality checks' cycle-agreement limits must leave room for."""
    parts = []
    for kind, errs in single.items():
        e = np.asarray(errs, dtype=float)
        e = e[np.isfinite(e)]
        g = np.asarray(gaps[kind], dtype=float)
        if e.size < 2 or g.size == 0:
            continue
        parts.append(f"{kind} {e.mean():+.2f} +- {e.std(ddof=1):.2f} deg, cycles apart "
                     f"max {g.max():.2f} (>3 deg: {(g > 3).sum()}, >5 deg: {(g > 5).sum()} "
                     f"of {g.size})")
    return "- one half-cycle against the tip: " + "; ".join(parts) + "\n"


def compare_protocols(paper: Sequence[GridPoint], fast: Sequence[GridPoint]) -> str:
    """The fast protocol's values, interpolated over the other knob's angle as a profile is
    (pchip), at every grid point of the paper protocol: against the paper protocol's values and
    against the tip measured in the paper protocol's sweeps."""
    lines = ["| parameter | max abs(fast - paper) (deg) | mean (deg) | max abs(fast - tip) (deg) "
             "| fast within 2 deg of the tip |", "|---|---|---|---|---|"]
    truths = {(p.knob, p.other_deg): tip_truth(p) for p in paper}
    for param in PARAMETERS:
        diffs: list[float] = []
        tip_errors: list[float] = []
        for knob in (0, 1):
            found = sorted((f.other_deg, f.result.estimate(param)) for f in fast if f.knob == knob)
            finite = [(x, y) for x, y in found if math.isfinite(y)]
            if len(finite) < 2:
                continue
            curve = PchipInterpolator(*zip(*finite, strict=True), extrapolate=True)
            for p in paper:
                if p.knob != knob:
                    continue
                value = float(curve(p.other_deg))
                diffs.append(abs(value - p.result.estimate(param)))
                tip_errors.append(abs(value - truths[(p.knob, p.other_deg)].get(param, math.nan)))
        d = np.asarray([x for x in diffs if math.isfinite(x)])
        e = np.asarray([x for x in tip_errors if math.isfinite(x)])
        lines.append(f"| {SHORT[param]} | {d.max() if d.size else math.nan:.1f} | "
                     f"{d.mean() if d.size else math.nan:.2f} | "
                     f"{e.max() if e.size else math.nan:.1f} | "
                     f"{int((e <= TARGET_DEG).sum())} of {e.size} |")
    return ("Fast protocol (interpolated over the other knob's angle) at the paper protocol's "
            "grid points:\n\n" + "\n".join(lines))


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
