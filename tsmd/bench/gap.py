"""`tsmd bench gap`: wall time of a diagnosis of a long recording, and the blind self-test.

Speed: a recording of ``--duration-s`` at ``--rate-hz`` (default 10 min at 250 Hz = 150,000 rows)
is made by the built-in plant with the coupling effect on (see :mod:`tsmd.gap.selftest`; making
it is not timed), then diagnosed with the default settings; the figure is the diagnosis wall time.
``--selftest`` then runs the self-test grid (cases x sizes x seeds) and prints its scores.
``--effect-sizes`` prints how much each self-test effect moves the tip and current before any
diagnosis (the criterion its strength is chosen by), optionally for another plant version.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from tsmd.gap.crosstest import cross_config, run_crosstest
from tsmd.gap.data import series_from_recording
from tsmd.gap.diagnose import diagnose
from tsmd.gap.errors import GapError
from tsmd.gap.presets import parse_plant_spec
from tsmd.gap.result import GapConfig
from tsmd.gap.score import selftest_markdown
from tsmd.gap.selftest import (
    BUILTIN_FIT_SPECS,
    BUILTIN_PLANT,
    EFFECTS,
    TRAJECTORIES,
    builtin_factory,
    effect_size,
    make_real_recording,
    run_selftest,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--duration-s", type=float, default=1800.0)
    parser.add_argument("--rate-hz", type=float, default=250.0)
    parser.add_argument("--case", default="coupling", choices=sorted(EFFECTS))
    parser.add_argument("--skip-speed", action="store_true", help="only the self-test")
    parser.add_argument("--selftest", action="store_true", help="also run the self-test grid")
    parser.add_argument("--sizes", default="120,300")
    parser.add_argument("--seeds", default="0,1")
    parser.add_argument("--cases", default=",".join(EFFECTS))
    parser.add_argument("--selftest-rate-hz", type=float, default=50.0)
    parser.add_argument("--trajectory", default="experiment", choices=sorted(TRAJECTORIES),
                        help="self-test motion: the identification experiment (default) or the "
                             "earlier single-speed sweeps, for comparison")
    parser.add_argument("--effect-sizes", action="store_true",
                        help="print each self-test effect's size on the tip and current (effect "
                             "on vs off, noise-free) over the self-test grid, then stop")
    parser.add_argument("--effect-plant", default=BUILTIN_PLANT,
                        help="plant factory measured by --effect-sizes (module:factory; its "
                             "module must define DEFAULT_KNOBS)")
    parser.add_argument("--cross", default=None, metavar="DATA,SIM",
                        help="also run the blind cross-plant self-test in both directions "
                             "between these two plants (presets or module:factory[@json]), "
                             "e.g. capstan-other,capstan")
    parser.add_argument("--method", default="signature", choices=("signature", "candidates"))
    parser.add_argument("--out", default=None, help="also write the figures as JSON here")


def effect_sizes(args: argparse.Namespace) -> dict[str, object]:
    """Each effect's tip/current RMSE (effect on minus off) per grid run and over the grid."""
    cases = [c for c in args.cases.split(",") if c and c != "none"]
    sizes = [float(x) for x in args.sizes.split(",")]
    seeds = [int(x) for x in args.seeds.split(",")]
    out: dict[str, object] = {}
    print("| case | strength | tip RMSE per run (deg) | tip RMSE over the grid (deg) | "
          "current RMSE over the grid (mA) |")
    print("| --- | --- | --- | ---: | ---: |")
    for case in cases:
        runs = [effect_size(case, d, s, args.selftest_rate_hz, plant_spec=args.effect_plant,
                            motion=args.trajectory) for d in sizes for s in seeds]
        tip = float(np.sqrt(np.mean([r.tip_rmse_deg**2 for r in runs])))
        cur = float(np.sqrt(np.mean([r.cur_rmse_A**2 for r in runs])))
        effects, lag_s, _ = EFFECTS[case]
        strength = ", ".join(f"{k} {v:g}" for k, v in effects.items()) or f"lag {lag_s:g} s"
        per_run = " / ".join(f"{r.tip_rmse_deg:.2f}" for r in runs)
        print(f"| {case} | {strength} | {per_run} | {tip:.2f} | {1e3 * cur:.1f} |", flush=True)
        out[case] = {"strength": strength, "tip_rmse_deg": tip, "cur_rmse_A": cur,
                     "runs": [vars(r) for r in runs]}
    return out


def main(args: argparse.Namespace) -> int:
    figures: dict[str, object] = {}
    if args.effect_sizes:
        figures["effect_sizes"] = effect_sizes(args)
        args.skip_speed = True
        args.selftest = False
    if not args.skip_speed:
        t0 = time.perf_counter()
        rec = make_real_recording(args.case, args.duration_s, args.rate_hz, seed=0)
        made_s = time.perf_counter() - t0
        series = series_from_recording(rec, f"bench-{args.case}")
        t1 = time.perf_counter()
        c1 = time.process_time()
        result = diagnose([series], builtin_factory(), {},
                          GapConfig(fit_specs=BUILTIN_FIT_SPECS, method=args.method))
        wall = time.perf_counter() - t1
        cpu = time.process_time() - c1
        print(f"recording: {len(series)} rows ({args.duration_s:.0f} s at {args.rate_hz:.0f} Hz, "
              f"case {args.case}), made in {made_s:.1f} s (not timed)")
        print(f"diagnosis wall time: {wall:.1f} s (target <= 60 s); CPU time of this process "
              f"{cpu:.1f} s (what a loaded machine does not inflate)")
        print("  stages: " + ", ".join(f"{k} {v:.1f} s" for k, v in result.timing_s.items()))
        print(f"  plant steps simulated: {result.rows['simulated']}, model evaluations: "
              f"{result.rows['model_evaluations']}, fit stride {result.rows['fit_stride']}, "
              f"held-out rows scored at full rate: {result.rows['held_out']}")
        print(f"  verdict: {result.verdict}; top: {result.top}")
        figures["speed"] = {"rows": len(series), "wall_s": wall, "cpu_s": cpu,
                            "timing_s": result.timing_s, "rows_detail": result.rows,
                            "verdict": result.verdict}
    if args.selftest or (args.skip_speed and not args.effect_sizes):
        cases = [c for c in args.cases.split(",") if c]
        sizes = [float(x) for x in args.sizes.split(",")]
        seeds = [int(x) for x in args.seeds.split(",")]
        st = run_selftest(cases, sizes, seeds, args.selftest_rate_hz,
                          progress=lambda c: print(
                              f"  {c.case:<11} {c.duration_s:5.0f} s seed {c.seed}: "
                              f"{c.verdict:<26} top={c.top or 'none':<11} ({c.wall_s:.1f} s)",
                              flush=True), motion=args.trajectory,
                          config=GapConfig(fit_specs=BUILTIN_FIT_SPECS, method=args.method))
        print(selftest_markdown(st))
        figures["selftest"] = {"summary": st.summary(), "confusion": st.confusion(),
                               "cases": [vars(c) for c in st.cases]}
    if args.cross:
        figures["cross"] = cross(args)
    if args.out:
        path = Path(args.out)
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(figures, indent=2), encoding="utf-8")
    return 0


def cross(args: argparse.Namespace) -> dict[str, object]:
    """The cross-plant self-test, data of each plant diagnosed with the other as simulator."""
    names = [x.strip() for x in args.cross.split(",")]
    if len(names) != 2:
        raise GapError(f"--cross {args.cross!r}: give two plants, DATA,SIM")
    plants = [parse_plant_spec(n) for n in names]
    cases = [c for c in args.cases.split(",") if c]
    sizes = [float(x) for x in args.sizes.split(",")]
    seeds = [int(x) for x in args.seeds.split(",")]
    out: dict[str, object] = {}
    for data, sim in (plants, plants[::-1]):
        label = f"data {data.name} / simulator {sim.name}"
        print(f"cross-plant self-test, {label}:", flush=True)
        st = run_crosstest(data, sim, cases, sizes, seeds, args.selftest_rate_hz,
                           cross_config(sim.fit, args.method),
                           progress=lambda c: print(
                               f"  {c.case:<11} {c.duration_s:5.0f} s seed {c.seed}: "
                               f"{c.verdict:<26} top={c.top or 'none':<11} ({c.wall_s:.1f} s)",
                               flush=True))
        print(selftest_markdown(st), flush=True)
        out[label] = {"summary": st.summary(), "confusion": st.confusion(),
                      "cases": [vars(c) for c in st.cases]}
    return out
