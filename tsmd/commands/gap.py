"""`tsmd gap`: diagnose the sim-to-real gap from real recordings (see docs/gap.md).

``tsmd gap RECORDING...`` writes ``gap_report.md``, ``gap_report.json`` and PNG plots to
``--out``. ``tsmd gap selftest`` runs the blind self-test on data made by the built-in plant.
``tsmd gap protocol --out FILE.csv`` writes the matched-condition protocol as a trajectory for
``tsmd replay``, whose recording then carries the protocol's segment labels. ``tsmd gap sheet
RECORDING...`` measures the data-sheet figure ``--compliance-sheet`` takes from the protocol
recorded with a reference unit of the catheter model.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from simrig.plant import load_plant
from tsmd.gap.compliance import reference_deg_per_A
from tsmd.gap.contrast import product_reference
from tsmd.gap.crosstest import cross_config, run_crosstest
from tsmd.gap.data import GapSeries, parse_holdout, series_from_recording
from tsmd.gap.diagnose import diagnose
from tsmd.gap.errors import GapError
from tsmd.gap.fit import ParamSpec
from tsmd.gap.presets import PRESETS, parse_plant_spec
from tsmd.gap.protocol import protocol_trajectory
from tsmd.gap.reference import ProductReference
from tsmd.gap.report import finite_json, write_report
from tsmd.gap.result import GapConfig
from tsmd.gap.score import selftest_markdown
from tsmd.gap.selftest import (
    BUILTIN_FIT_SPECS,
    BUILTIN_PLANT,
    EFFECTS,
    complete_knobs,
    run_selftest,
)
from tsmd.recording import Recording, read_recording, write_trajectory
from tsmd.tee import load_tee_acquisition


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("recordings", nargs="+", metavar="RECORDING",
                        help="recording CSV files (tsmd recording format; with --tee raw TEE "
                             "CSVs), or the word 'selftest', 'protocol' or 'sheet' followed "
                             "by the reference unit's protocol recordings")
    parser.add_argument("--plant", default=BUILTIN_PLANT,
                        help="simulator plant 'module:factory' (default: the built-in plant)")
    parser.add_argument("--params", default=None,
                        help="plant parameters: a JSON/YAML file or an inline JSON object")
    parser.add_argument("--fit", action="append", default=None, metavar="NAME=LO:HI[@KNOB]",
                        help="a plant parameter to fit (dotted path, bounds, knob 1 or 2 whose "
                             "channels judge it; 'a+b' moves a and b together); repeat. Default "
                             "for the built-in plant: slack per side and sheath friction of "
                             "each knob")
    parser.add_argument("--holdout", default="0.3",
                        help="held-out fraction of interleaved time blocks, or comma-separated "
                             "recording file names held out whole (default 0.3)")
    parser.add_argument("--block-s", type=float, default=None,
                        help="time block length in s (default: total duration / 48, >= 1 s)")
    parser.add_argument("--out", default="gap-report", help="output directory")
    parser.add_argument("--seed", type=int, default=0, help="bootstrap seed")
    parser.add_argument("--fit-rows", type=int, default=2000,
                        help="rows simulated per fit evaluation (thinning; default 2000)")
    parser.add_argument("--joint-top", type=int, default=2, metavar="K",
                        help="refit the K best screened candidates jointly with the base "
                             "parameters, so an effect the base fit absorbed can show "
                             "(default 2; 0 = off, faster)")
    parser.add_argument("--tee", action="store_true",
                        help="inputs are raw TEE acquisitions (converted by tsmd.tee)")
    parser.add_argument("--compliance-sheet", default=None, metavar="DEG_PER_A,DEG_PER_A",
                        help="the catheter model's data-sheet lost motion per ampere at a "
                             "reversal, knob 1 and 2 (`tsmd gap sheet` on another unit's "
                             "protocol recordings); with it and the protocol in the recordings "
                             "tendon compliance can be named")
    parser.add_argument("--model-reference", default=None, metavar="REC,REC...",
                        help="the protocol recorded on reference units of the catheter model "
                             "(the data sheet's unit, better several: the header's catheter "
                             "tells them apart): what the model has always (its own rate, "
                             "coupling and creep contrasts) and, from two or more units, how "
                             "far a unit may lie from it; effects are then named only for what "
                             "a unit has beyond that. Its units' lost motion per ampere is the "
                             "compliance sheet then, in place of --compliance-sheet")
    parser.add_argument("--sizes", default="120,300",
                        help="selftest: recording lengths in s (comma-separated)")
    parser.add_argument("--seeds", default="0,1", help="selftest: noise/unit seeds")
    parser.add_argument("--cases", default=",".join(EFFECTS),
                        help=f"selftest: cases ({', '.join(EFFECTS)})")
    parser.add_argument("--rate-hz", type=float, default=None,
                        help="selftest: sample rate (default 50); protocol: the loop rate the "
                             "trajectory is made for (default 250)")
    parser.add_argument("--configuration", default="",
                        help="protocol: the set-up label written into the trajectory's header "
                             "(e.g. straight, looped); the replay's recording carries it")
    parser.add_argument("--method", default="signature", choices=("signature", "candidates"),
                        help="effects by their condition signature on top of a structural "
                             "hysteresis layer (default; holds when the base physics differ), "
                             "or the earlier candidate transforms around the plant")
    parser.add_argument("--data-plant", default=None, metavar="SPEC",
                        help="selftest across plants: the plant that makes the 'real' data "
                             f"(preset {', '.join(PRESETS)}, or module:factory[@{{json}}])")
    parser.add_argument("--sim-plant", default=None, metavar="SPEC",
                        help="selftest across plants: the plant used as the simulator")
    parser.add_argument("--sheet-unit", type=int, default=0, metavar="N",
                        help="selftest across plants: the unit of the data plant whose protocol "
                             "gives the compliance data sheet (default 0, the nominal unit; "
                             "never one of --seeds)")
    parser.add_argument("--reference-units", default="0,5,6,7,8", metavar="N,N...",
                        help="selftest across plants: the units of the data plant the model "
                             "reference is measured on (what the model has always, and from "
                             "their spread how far a unit may lie from it; default 0,5,6,7,8; "
                             "never one of --seeds; one unit: no spread, as in session 12)")
    parser.add_argument("--no-reference", action="store_true",
                        help="selftest across plants: no model reference; every rate, "
                             "coupling and creep contrast is then named, as before session 12")
    parser.add_argument("--no-protocol", action="store_true",
                        help="selftest across plants: sessions without the matched-condition "
                             "protocol recordings (the experiment motion only, as before)")


def _load_params(text: str | None) -> dict[str, Any]:
    if text is None:
        return {}
    path = Path(text)
    try:
        raw = path.read_text(encoding="utf-8") if path.exists() else text
        data = yaml.safe_load(raw)
    except (OSError, yaml.YAMLError) as exc:
        raise GapError(f"--params {text!r}: cannot read as a JSON/YAML mapping: {exc}") from exc
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise GapError(f"--params {text!r}: must be a mapping of plant parameters")
    return data


def parse_fit_spec(text: str) -> ParamSpec:
    """``NAME=LO:HI`` or ``NAME=LO:HI@KNOB`` (knob 1 or 2)."""
    name, sep, rest = text.partition("=")
    knob: int | None = None
    if "@" in rest:
        rest, _, knob_text = rest.partition("@")
        if knob_text not in ("1", "2"):
            raise GapError(f"--fit {text!r}: knob after '@' must be 1 or 2")
        knob = int(knob_text) - 1
    lo_text, sep2, hi_text = rest.partition(":")
    try:
        lo, hi = float(lo_text), float(hi_text)
    except ValueError:
        raise GapError(f"--fit {text!r}: expected NAME=LO:HI[@KNOB]") from None
    if not sep or not sep2 or not name.strip() or not lo < hi:
        raise GapError(f"--fit {text!r}: expected NAME=LO:HI[@KNOB] with LO < HI")
    return ParamSpec(name.strip(), lo, hi, knob)


def _load_recording(path: str, tee: bool) -> GapSeries:
    if tee:
        rec: Recording = load_tee_acquisition(path)
    else:
        rec = read_recording(path, required=("t",))
    return series_from_recording(rec, Path(path).name)


def _factory(spec: str, fixed: dict[str, Any]) -> Any:
    load_plant(spec, fixed)  # fail early, with the loader's message

    def factory(params: dict[str, Any]) -> Any:
        return load_plant(spec, complete_knobs(params) if spec == BUILTIN_PLANT else params)

    return factory


def main(args: argparse.Namespace) -> int:
    if args.recordings[0] == "selftest":
        return _selftest(args)
    if args.recordings[0] == "protocol":
        return _protocol(args)
    if args.recordings[0] == "sheet":
        return _sheet(args)
    series = [_load_recording(p, args.tee) for p in args.recordings]
    names = [s.name for s in series]
    if len(set(names)) != len(names):
        raise GapError(f"recording file names must differ: {names}")
    params = _load_params(args.params)
    if args.fit is not None:
        specs = tuple(parse_fit_spec(t) for t in args.fit)
    elif args.plant == BUILTIN_PLANT:
        specs = BUILTIN_FIT_SPECS
    else:
        specs = ()
    holdout = parse_holdout(args.holdout)
    config = GapConfig(fit_specs=specs,
                       holdout=holdout if isinstance(holdout, float) else tuple(holdout),
                       block_s=args.block_s, fit_max_rows=max(args.fit_rows, 200),
                       joint_top=max(args.joint_top, 0), seed=args.seed,
                       method=args.method,
                       compliance_reference=_compliance_sheet(args.compliance_sheet),
                       product_reference=_model_reference(args.model_reference, args.tee))
    result = diagnose(series, _factory(args.plant, params), params, config)
    out = Path(args.out)
    md, js = write_report(result, out, ", ".join(names),
                          {"plant": args.plant, "recordings": names})
    print(f"verdict: {result.verdict}")
    print(result.summary)
    print(f"report: {md}  data: {js}  ({result.timing_s['total']:.1f} s)")
    return 0


def _compliance_sheet(text: str | None) -> tuple[float, float] | None:
    if text is None:
        return None
    try:
        k1, k2 = (float(x) for x in text.split(","))
    except ValueError:
        raise GapError(f"--compliance-sheet {text!r}: expected two numbers, "
                       "DEG_PER_A,DEG_PER_A") from None
    if not (k1 > 0.0 and k2 > 0.0 and np.isfinite(k1) and np.isfinite(k2)):
        raise GapError(f"--compliance-sheet {text!r}: both figures must be positive")
    return k1, k2


def _model_reference(text: str | None, tee: bool) -> ProductReference | None:
    if text is None:
        return None
    paths = [p.strip() for p in text.split(",") if p.strip()]
    if not paths:
        raise GapError("--model-reference: give the reference unit's protocol recordings")
    reference = product_reference([_load_recording(p, tee) for p in paths])
    if not reference.loops and reference.creep is None:
        raise GapError(f"--model-reference {text!r}: no protocol segments (rate, coupling or "
                       "creep) in these recordings")
    return reference


def _sheet(args: argparse.Namespace) -> int:
    paths = args.recordings[1:]
    if not paths:
        raise GapError("tsmd gap sheet RECORDING...: give the reference unit's protocol "
                       "recordings")
    figure = reference_deg_per_A([_load_recording(p, args.tee) for p in paths])
    if figure is None:
        raise GapError("tsmd gap sheet: too few readable reversals at the protocol's 40 and "
                       "60 deg in these recordings (do they carry the protocol's segments?)")
    print(f"lost motion per ampere: knob 1 {figure[0]:.4g}, knob 2 {figure[1]:.4g} deg/A; "
          f"diagnose other units with --compliance-sheet {figure[0]:.4g},{figure[1]:.4g}")
    return 0


def _protocol(args: argparse.Namespace) -> int:
    rate_hz = 250.0 if args.rate_hz is None else args.rate_hz
    if not 10.0 <= rate_hz <= 1000.0:
        raise GapError(f"--rate-hz {rate_hz:g}: the loop runs at 10-1000 Hz")
    out = Path(args.out if args.out.endswith(".csv") else f"{args.out}/protocol.csv")
    traj = protocol_trajectory(rate_hz, args.configuration.strip())
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        write_trajectory(out, traj)
    except OSError as exc:
        raise GapError(f"--out {out}: cannot write: {exc.strerror or exc}") from None
    print(f"protocol: {traj['t'][-1]:.0f} s at {rate_hz:g} Hz -> {out}; play it with "
          f"`tsmd replay --trajectory {out} --no-compensation --out RECORDING.csv` "
          "(loop.rate_hz the same)")
    return 0


def _selftest(args: argparse.Namespace) -> int:
    cases = [c.strip() for c in args.cases.split(",") if c.strip()]
    unknown = [c for c in cases if c not in EFFECTS]
    if unknown:
        raise GapError(f"unknown selftest case(s) {unknown}; known: {', '.join(EFFECTS)}")
    try:
        sizes = [float(x) for x in args.sizes.split(",")]
        seeds = [int(x) for x in args.seeds.split(",")]
        ref_units = [int(x) for x in args.reference_units.split(",")]
    except ValueError:
        raise GapError("--sizes, --seeds and --reference-units take comma-separated "
                       "numbers") from None

    def progress(c: Any) -> None:
        print(f"  {c.case:<11} {c.duration_s:5.0f} s seed {c.seed}: {c.verdict:<26} "
              f"top={c.top or 'none':<11} ({c.wall_s:.1f} s)", flush=True)

    rate_hz = 50.0 if args.rate_hz is None else args.rate_hz
    if args.data_plant or args.sim_plant:

        data = parse_plant_spec(args.data_plant or "capstan-other")
        sim = parse_plant_spec(args.sim_plant or "capstan")
        for case in cases:
            if not data.supports(case):
                print(f"  {case}: not run, the data plant {data.name or data.factory} has no "
                      "such effect in its physics", flush=True)
        result = run_crosstest(data, sim, cases, sizes, seeds, rate_hz,
                               cross_config(sim.fit, args.method), progress=progress,
                               matched=not args.no_protocol, sheet_unit=args.sheet_unit,
                               reference_units=() if args.no_reference else ref_units)
    else:
        result = run_selftest(cases, sizes, seeds, rate_hz,
                              GapConfig(fit_specs=BUILTIN_FIT_SPECS, method=args.method),
                              progress=progress)
    text = selftest_markdown(result)
    print(text)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "gap_selftest.md").write_text(text + "\n", encoding="utf-8")
    (out / "gap_selftest.json").write_text(json.dumps(finite_json(
        {"summary": result.summary(), "confusion": result.confusion(),
         "cases": [vars(c) for c in result.cases]}), indent=2), encoding="utf-8")
    return 0
