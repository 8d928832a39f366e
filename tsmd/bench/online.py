"""`tsmd bench online`: online re-estimation of the dead zone through a shape change.

Every run is the full stack in lockstep (simulated CiA 402 drives, the control loop, our
compensator) on one catheter of a plant's family (``simrig.family``: ``--plant capstan`` is the
development plant, ``lumped`` the held-out one; units 1-8 development, 101-108 held out). The
worker is the loop's observer and is drained synchronously every 25 ticks (deterministic); the
estimator sees only commanded and actual position and current. Per unit:

- the unit is calibrated from current (fast protocol) before the change, and again, freshly,
  with the changed shape (the reference a new calibration would give);
- one mixed-motion trajectory (both knobs, two sines each, so reversals happen on the loaded
  ramps and inside the dead zone) is played three times: the shape changes at ``--change-at``
  with online re-estimation on, the same with it off, and on the changed plant with the fresh
  profile. Tip RMSE (simulated tracker, evaluation only) is compared from each knob's 10th
  reversal after the change to the end;
- ``--drift-s`` > 0: no change, :func:`drift_motion` (periodic, non-periodic, dwells, both
  knobs) online on and off: each edge's largest offset against the calibration's uncertainty,
  and the tracking of both runs.

``--start calibrated`` (the default, session 26): every run goes on from a copy of the plant
its calibration left (:mod:`tsmd.bench.online_start`), as a probe calibrated in the patient is
used soaked and warm; ``fresh``: a newly built plant (dry, cold), as until session 25.

``--bend-relation daemon`` (the default): the worker gets the data sheet's bend relation when
the sheet carries one and none otherwise, as the daemon's does. ``sheet``: a sheet without one
gets it measured on unit 0 as ``tsmd datasheet --bend-relation`` would
(:mod:`tsmd.bench.online_bend`; ``unit0``, session 11's name, is the same); ``off``: none even
where the sheet has one (the default until session 22). ``--sheet FILE``: the product's data
sheet to use instead. The data sheet of the lumped family is measured once on its nominal unit
(tracker on the tip, ``tsmd.datasheet``); capstan units use
``profiles/devices/sim-catheter.yaml``. Data sheets and calibrated profiles are cached in
``--cache``, in a subdirectory keyed by the code that made them (:mod:`tsmd.bench.cache_key`),
by plant, unit and shape, so reruns are cheap.
"""

from __future__ import annotations

import argparse
import itertools
import math
import time
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from simrig.family import PLANT_ROLE, PLANT_SPECS
from simrig.scenario import ShapeChange
from tsmd.bench.cache_key import keyed_cache
from tsmd.bench.online_bend import product_bend_relation
from tsmd.bench.online_start import STARTS, calibrated_with_plant, run_plant
from tsmd.bench.online_units import calibrated, device_for, shape_change
from tsmd.calibration.errors import CalibrationRefusedError
from tsmd.compensation import build_compensator
from tsmd.errors import TsmdError
from tsmd.loop import ROW_COLUMNS
from tsmd.online import OnlineWorker
from tsmd.online.bend import sheet_bend_relation
from tsmd.online.rig_run import PERIOD_S, mixed_motion, run
from tsmd.profile import load_device_model, load_profile

Array = NDArray[np.float64]
REVERSALS = 10
CALIBRATION_UNCERTAINTY_DEG = 0.5
"""One half-cycle's knee edge against the tip's, standard deviation (docs/calibration.md)."""


def reversal_times(t: Array, q: Array, after_s: float) -> Array:
    """Times where the desired angle turns back (any size), after ``after_s``."""
    dq = np.diff(q)
    s = np.sign(dq)
    idx = np.nonzero((s[1:] * s[:-1]) < 0)[0] + 1
    times = t[idx]
    return times[times > after_s]


def rmse(rec: Any, knob: int, t0: float, t1: float = math.inf) -> float:
    sel = (rec["t"] >= t0) & (rec["t"] < t1)
    e = rec[f"tip{knob + 1}"][sel] - rec[f"q{knob + 1}"][sel]
    return float(np.sqrt(np.mean(e * e)))


def unit_profile(args: argparse.Namespace, unit: int, change: dict[str, Any] | None,
                 device: Any, label: str) -> tuple[Any, Any]:
    """The unit's calibrated profile and, for ``--start calibrated``, the plant the calibration
    left (None for ``--start fresh``, which needs only the profile)."""
    cache = Path(args.cache)
    if args.start == "fresh":
        return calibrated(args.plant, unit, change, device, cache, label), None
    return calibrated_with_plant(args.plant, unit, change, device, cache, label)


def change_unit(unit: int, args: argparse.Namespace, device: Any) -> dict[str, Any]:

    change = shape_change(args.change)
    before, before_plant = unit_profile(args, unit, None, device, "straight")
    try:
        fresh, fresh_plant = unit_profile(args, unit, change, device,
                                          args.change.replace(":", "-"))
    except CalibrationRefusedError as exc:  # reported, compared with before the change only
        fresh, fresh_plant, refused = None, None, str(exc)
    else:
        refused = ""
    t, q = mixed_motion(args.change_at + args.after_s, args.seed)
    at = args.change_at
    t0 = time.perf_counter()
    rec_on, worker = run(before, run_plant(args.start, args.plant, unit, before_plant,
                                           [ShapeChange(at, change)]),
                         t, q, True, args.seed, device, args.bend)
    rec_off, _ = run(before, run_plant(args.start, args.plant, unit, before_plant,
                                       [ShapeChange(at, change)]),
                     t, q, False, args.seed)
    rec_fresh = None
    if fresh is not None:
        # a calibrated plant already has the changed shape; a fresh one gets it at once
        rec_fresh, _ = run(fresh, run_plant(args.start, args.plant, unit, fresh_plant,
                                            [] if args.start == "calibrated"
                                            else [ShapeChange(0.0, change)]),
                           t, q, False, args.seed)
    wall = time.perf_counter() - t0
    out: dict[str, Any] = {"unit": unit, "wall_s": wall, "knobs": [], "refused": refused}

    def fresh_rmse(knob: int, a: float, b: float = math.inf) -> float:
        return math.nan if rec_fresh is None else rmse(rec_fresh, knob, a, b)

    for k in (0, 1):
        revs = reversal_times(t, q[:, k], at)
        if len(revs) < REVERSALS:
            raise TsmdError(f"only {len(revs)} reversals of knob {k + 1} after the change; "
                            "lengthen --after-s")
        t10 = float(revs[REVERSALS - 1])
        trend = [rmse(rec_on, k, float(a), float(b)) / max(fresh_rmse(k, float(a), float(b)),
                                                            1e-9)
                 for a, b in itertools.pairwise(revs[:REVERSALS + 1])]
        out["knobs"].append({
            "before": rmse(rec_on, k, 10.0, at), "before_off": rmse(rec_off, k, 10.0, at),
            "on": rmse(rec_on, k, t10),
            "off": rmse(rec_off, k, t10), "fresh": fresh_rmse(k, t10), "t10": t10 - at,
            "trend": trend})
    assert worker is not None
    out["offsets"] = worker.offsets()
    out["events"] = [e for e in worker.events if e["level"] == "warning"]
    out["max_before_deg"] = max([abs(e["offset_deg"]) for e in worker.events
                                 if e["event"] == "online offset" and e["t"] < at], default=0.0)
    return out


def drift_motion(duration_s: float, seed: int) -> tuple[Array, Array]:
    """Mixed use without a shape change: 60 s blocks that alternate between the periodic
    :func:`mixed_motion` and random moves of each knob between random angles (2-6 s each) with
    dwells (3-10 s, a third of the time), blended over 2 s so the command stays smooth."""
    rng = np.random.default_rng(seed)
    t, periodic = mixed_motion(duration_s, seed)
    moves = np.zeros_like(periodic)
    for k in (0, 1):
        knots_t, knots_q = [0.0], [0.0]
        while knots_t[-1] < duration_s:
            if rng.uniform() < 1.0 / 3.0:  # a dwell: the knob holds where it is
                knots_t.append(knots_t[-1] + rng.uniform(3.0, 10.0))
                knots_q.append(knots_q[-1])
            knots_t.append(knots_t[-1] + rng.uniform(2.0, 6.0))
            knots_q.append(rng.uniform(-55.0, 55.0))
        seg = np.searchsorted(knots_t, t, side="right") - 1
        t0, t1 = np.asarray(knots_t)[seg], np.asarray(knots_t)[seg + 1]
        q0, q1 = np.asarray(knots_q)[seg], np.asarray(knots_q)[seg + 1]
        w = 0.5 - 0.5 * np.cos(math.pi * (t - t0) / (t1 - t0))  # cosine move, rests at knots
        moves[:, k] = q0 + w * (q1 - q0)
    phase = np.clip(np.abs(((t + 30.0) % 120.0) - 60.0) - 29.0, 0.0, 2.0) / 2.0  # 0..1 blend
    blend = 0.5 - 0.5 * np.cos(math.pi * phase)
    return t, (1.0 - blend)[:, None] * periodic + blend[:, None] * moves


def largest_offsets(worker: Any) -> dict[str, float]:
    """Each edge's largest applied offset over the run (the worker's ``online offset`` events),
    deg, keyed ``phi1_pos`` ..."""
    out = {f"phi{k + 1}_{s}": 0.0 for k in (0, 1) for s in ("pos", "neg")}
    for e in worker.events:
        if e["event"] == "online offset":
            key = f"phi{e['knob'] + 1}_{e['side']}"
            out[key] = max(out[key], abs(float(e["offset_deg"])))
    return out


def drift_unit(unit: int, args: argparse.Namespace, device: Any) -> dict[str, Any]:
    profile, calibrated_plant = unit_profile(args, unit, None, device, "straight")
    t, q = drift_motion(args.drift_s, args.seed + 100)
    t0 = time.perf_counter()
    rec_on, worker = run(profile, run_plant(args.start, args.plant, unit, calibrated_plant, []),
                         t, q, True, args.seed, device, args.bend)
    wall_on = time.perf_counter() - t0
    rec_off, _ = run(profile, run_plant(args.start, args.plant, unit, calibrated_plant, []),
                     t, q, False, args.seed)
    assert worker is not None
    status = worker.status()
    return {"unit": unit, "wall_on_s": wall_on, "offsets": worker.offsets(),
            "largest": largest_offsets(worker),
            "on": [rmse(rec_on, k, 10.0) for k in (0, 1)],
            "off": [rmse(rec_off, k, 10.0) for k in (0, 1)],
            "ramps": {name: e["ramps"] for name, e in status["edges"].items()},
            "warnings": [e for e in worker.events if e["level"] == "warning"]}


def hot_path_us(n: int = 20000) -> tuple[float, float, float]:
    """Median, p99 and max wall time of the loop-side ``observe`` for two knobs, with the
    worker draining on its own thread every 50 ms (as in the daemon)."""
    profile = load_profile(Path(__file__).resolve().parents[2] / "profiles" / "example-sim.yaml")
    comp = build_compensator(profile, "ours", PERIOD_S)
    worker = OnlineWorker(comp, PERIOD_S, ROW_COLUMNS)
    t, q = mixed_motion(n * PERIOD_S, 0)
    rows = [(float(t[i]), float(q[i, 0]), float(q[i, 1]), float(q[i, 0]), float(q[i, 1]),
             float(q[i, 0]), float(q[i, 1]), 0.05, 0.05, math.nan, math.nan) for i in range(n)]
    times = np.empty(n)
    worker.start()
    try:
        for i, row in enumerate(rows):
            if i % 500 == 0:  # a published update every 2 s: the pick-up is timed too
                worker.published = (worker.published[0] + 1, worker.published[1],
                                    worker.published[2])
            t0 = time.perf_counter_ns()
            worker.observe(row, True)
            times[i] = time.perf_counter_ns() - t0
            time.sleep(0)  # let the worker thread run between ticks
    finally:
        worker.stop()
    return (float(np.median(times) / 1e3), float(np.percentile(times, 99) / 1e3),
            float(times.max() / 1e3))


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--plant", choices=sorted(PLANT_SPECS), default="capstan",
                        help="the family: " + ", ".join(
                            f"{name} ({role})" for name, role in PLANT_ROLE.items()))
    parser.add_argument("--units", default="0,1,2",
                        help="units of the family (0 nominal, 1-8 development, 101-108 held out)")
    parser.add_argument("--change", default="slack:0.5",
                        help="slack:MM (all tendons) or curvature:DEG (sheath bend)")
    parser.add_argument("--change-at", type=float, default=80.0, help="plant time of the change")
    parser.add_argument("--after-s", type=float, default=110.0, help="run time after the change")
    parser.add_argument("--drift-s", type=float, default=0.0,
                        help="also run this long without a change, online on and off")
    parser.add_argument("--seed", type=int, default=0, help="noise and trajectory seed")
    parser.add_argument("--cache", default="/tmp/tsmd-bench-online",
                        help="calibrated profiles go in a subdirectory per code version")
    parser.add_argument("--no-change", action="store_true", help="skip the shape-change runs")
    parser.add_argument("--start", choices=STARTS, default="calibrated",
                        help="calibrated (default): every run goes on from the plant the "
                             "calibration left (soaked, warm, loaded, as a probe calibrated in "
                             "the patient); fresh: a newly built plant (dry, cold; until "
                             "session 26)")
    parser.add_argument("--sheet", metavar="FILE",
                        help="the product's data sheet (default: capstan's built-in one, "
                             "other plants' measured on unit 0 and cached)")
    parser.add_argument("--bend-relation", choices=("daemon", "sheet", "unit0", "off"),
                        default="daemon",
                        help="daemon (default): the data sheet's bend relation where it has one, "
                             "as the daemon runs; sheet (or unit0): measured on unit 0 when the "
                             "sheet has none (release line and beta move with the edges); off: "
                             "none, x0 moves with the edges")


def main(args: argparse.Namespace) -> int:
    try:
        units = [int(u) for u in str(args.units).split(",") if u.strip()]
    except ValueError:
        raise TsmdError(f"--units {args.units!r}: expected integers like 0,1,2") from None
    shape_change(args.change)  # a bad --change is refused before anything runs
    args.cache = str(keyed_cache(Path(args.cache)))
    print(f"profiles cached in {args.cache}")
    device = (device_for(args.plant, Path(args.cache)) if args.sheet is None
              else load_device_model(args.sheet))
    args.bend = None
    if args.bend_relation == "daemon":
        args.bend = sheet_bend_relation(device)
    elif args.bend_relation != "off":
        args.bend = product_bend_relation(args.plant, device, Path(args.cache))
    if args.bend is not None:
        source = ("the data sheet" if sheet_bend_relation(device) is not None
                  else "unit 0, bends 30/60/90 deg")
        print(f"bend relation ({source}): release line "
              f"{args.bend.release_per_edge:.3f} deg per edge deg, beta x (1 + "
              f"{args.bend.gain_per_release_deg:.4f} per release deg); without an edge move "
              f"beta x (1 + {args.bend.gain_per_slope:.3f} per slope rise), omega per gain "
              f"{args.bend.omega_per_gain}")
    med, p99, top = hot_path_us()
    print(f"hot path (loop-side observe, two knobs): median {med:.2f} us, p99 {p99:.2f} us, "
          f"max {top:.1f} us")
    refused_all = False
    if not args.no_change:
        print(f"\nshape change {args.change} at {args.change_at:g} s; RMSE from each knob's "
              f"{REVERSALS}th reversal after it to {args.after_s:g} s after it (tip deg)\n")
        print(f"{args.plant} family\n")
        print("| unit | knob | before (on / off) | online on | online off | fresh calibration | "
              "on / before | on / fresh | 10th reversal after (s) |")
        print("|---|---|---|---|---|---|---|---|---|")
        ratios: list[float] = []
        before_ratios: list[float] = []
        for u in units:
            try:
                r = change_unit(u, args, device)
            except CalibrationRefusedError as exc:  # the unit's own calibration: next unit
                print(f"| {u} | calibration before the change refused: "
                      f"{exc} | | | | | | | |", flush=True)
                continue
            for k, kn in enumerate(r["knobs"]):
                ratio = kn["on"] / kn["fresh"]
                vs_before = kn["on"] / kn["before"]
                ratios.append(ratio)
                before_ratios.append(vs_before)
                print(f"| {u} | phi{k + 1} | {kn['before']:.2f} / {kn['before_off']:.2f} | "
                      f"{kn['on']:.2f} | {kn['off']:.2f} | {kn['fresh']:.2f} | "
                      f"{vs_before:.2f} | {ratio:.2f} | {kn['t10']:.0f} |")
            trend = " / ".join(" ".join(f"{x:.1f}" for x in kn["trend"]) for kn in r["knobs"])
            offsets = [[round(v, 2) for v in pair] for pair in r["offsets"]]
            if r["refused"]:
                print(f"|   | fresh calibration after the change: {r['refused']} "
                      "| | | | | | | |")
            print(f"|   | offsets (deg, outward) {offsets}, largest before the change "
                  f"{r['max_before_deg']:.2f}; on/fresh per reversal "
                  f"interval phi1 / phi2: {trend}; {len(r['events'])} warnings; "
                  f"3 runs {r['wall_s']:.0f} s wall | | | | | | | |", flush=True)
        scored = [r for r in ratios if math.isfinite(r)]
        if not scored:
            print("\non / fresh: no unit scored (every calibration before or after the change "
                  "was refused: see the table)")
            refused_all = True
        ratios = scored or [math.nan]
        before_ratios = before_ratios or [math.nan]
        print(f"\non / fresh: mean {np.mean(ratios):.2f}, worst {max(ratios):.2f} "
              f"(target <= 1.2); on / before: mean {np.mean(before_ratios):.2f}, worst "
              f"{max(before_ratios):.2f}")
    if args.drift_s > 0:
        print(f"\nno change, {args.plant}, {args.drift_s:g} s of mixed motion (periodic, random "
              f"moves, dwells); largest offset of each edge over the run against the "
              f"calibration uncertainty ({CALIBRATION_UNCERTAINTY_DEG} deg)\n")
        print("| unit | largest offset phi1 pos/neg, phi2 pos/neg (deg) | within | ramps | "
              "RMSE on (phi1, phi2) | RMSE off | warnings | wall s (on) |")
        print("|---|---|---|---|---|---|---|---|")
        for u in units:
            try:
                d = drift_unit(u, args, device)
            except CalibrationRefusedError as exc:
                print(f"| {u} | calibration refused: {exc} | | | | | | |",
                      flush=True)
                continue
            big = d["largest"]
            within = all(v <= CALIBRATION_UNCERTAINTY_DEG for v in big.values())
            print(f"| {u} | {big['phi1_pos']:.2f}/{big['phi1_neg']:.2f}, "
                  f"{big['phi2_pos']:.2f}/{big['phi2_neg']:.2f} | {'yes' if within else 'NO'} | "
                  f"{sum(d['ramps'].values())} | {d['on'][0]:.2f}, {d['on'][1]:.2f} | "
                  f"{d['off'][0]:.2f}, {d['off'][1]:.2f} | {len(d['warnings'])} | "
                  f"{d['wall_on_s']:.0f} |", flush=True)
            for w in d["warnings"]:
                print(f"|   | warning at {w['t']:.0f} s: {w['event']} {w.get('reason', '')} "
                      "| | | | | | |")
    return 1 if refused_all else 0
