"""`tsmd datasheet`'s sample: its unit list, its part on a sheet being measured, and
``--update FILE``: the part added to an existing sheet with nothing else of it changed.

The part only widens the half-width a calibration reports (never a value, the gate or a
re-sweep: :class:`tsmd.calibration.estimate.Estimate`), so a shipped sheet can carry it without
being re-measured; its sample is calibrated under exactly that sheet (docs/calibration.md,
session 20).
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import json
import math
import re
import time
from pathlib import Path
from typing import Any

from simrig.family import DEVELOPMENT_UNITS, HELD_OUT_UNITS
from simrig.plant import load_plant
from tsmd import __version__
from tsmd.commands.datasheet_stick import (
    source_header,
    with_settle_gain_check,
    with_stick_choice,
)
from tsmd.commands.datasheet_sweep import with_sweep_start
from tsmd.config import TsmdConfig, default_sim_config, load_config
from tsmd.datasheet import DatasheetError
from tsmd.datasheet_home_hold import with_home_hold
from tsmd.datasheet_level_grid import with_level_grid
from tsmd.datasheet_plateau_gap import LOOP_KEYS, with_plateau_gap
from tsmd.datasheet_release_round import with_release_round
from tsmd.datasheet_sample import SAMPLE_KEYS, left_deg2, measure_sample
from tsmd.datasheet_slope_weight import sample_pairs, with_slope_weight
from tsmd.datasheet_start import DEFAULT_SHEET_START, sheet_unit_factory
from tsmd.datasheet_unit_edges import UNIT_EDGE_KEYS, with_unit_edges
from tsmd.profile import DeviceModel, load_device_model, save_device_fields, save_device_model

SCORED_UNITS = frozenset(DEVELOPMENT_UNITS + HELD_OUT_UNITS)
"""Units a figure is scored on (development and held out): never in a product's sample."""

MEASURING_OPTIONS = ("from_recording", "device_model", "loaded_shape", "tip_backlash_gain",
                     "tip_line_backlash_gain", "release_end_offset", "recovery_rule",
                     "bend_relation")
"""Options that measure a sheet anew: not with ``--update``."""


def sample_units(text: str, own_unit: object) -> list[int]:
    """``--unit-sample``: units and ranges (``201-208``), none scored, none twice, not the
    sheet's own unit (``own_unit``, always in the sample)."""
    units: list[int] = []
    for x in (x.strip() for x in text.split(",") if x.strip()):
        m = re.fullmatch(r"(\d+)(?:-(\d+))?", x)
        if m is None:
            raise DatasheetError(f"--unit-sample: not a comma-separated list of units or "
                                 f"ranges (201-208): {text!r}")
        last = int(m[2] if m[2] is not None else m[1])
        if last < int(m[1]):
            raise DatasheetError(f"--unit-sample: range {x} runs backwards")
        units += range(int(m[1]), last + 1)
    if not units:
        raise DatasheetError("--unit-sample: give at least one unit")
    scored = sorted(set(units) & SCORED_UNITS)
    if scored:
        raise DatasheetError(f"--unit-sample: unit(s) {','.join(map(str, scored))} are scored "
                             f"(development 1-8, held out 101-108); a sample never holds one")
    if len(set(units)) < len(units) or own_unit in units:
        raise DatasheetError("--unit-sample: a unit twice (the sheet's own unit is always in "
                             "the sample)")
    return units


def with_sample(device: DeviceModel, config: TsmdConfig, plant: str, params: dict[str, Any],
                unit_key: str, units: list[int], seed: int) -> DeviceModel:
    """The sheet with the product's parts of the error no sweep narrows, from its sample; each
    unit's mean square beyond the gate printed, so a sub-sample's part can be pooled again."""
    t0 = time.monotonic()
    configs = [config.replace(sim=dataclasses.replace(config.sim, plant=plant, params=p))
               for p in [params, *({**params, unit_key: u} for u in units)]]
    device, per_unit = measure_sample(device, configs, seed)
    kinds = (("D", "dead-zone edge"), ("B", "backlash"))
    for c, readings in zip(configs, per_unit, strict=True):
        print(f"  sample unit {c.sim.params.get(unit_key, 'sheet')}: " + "; ".join(
            f"{name} " + ", ".join(
                f"{short} {len(readings[(knob, kind)][0])} values, left "
                f"{_or_none(left_deg2(readings[(knob, kind)]), 3)} deg^2" for short, kind in kinds)
            for knob, name in enumerate(("phi1", "phi2"))))
    for knob, (name, k) in enumerate(zip(("phi1", "phi2"), device.knobs, strict=True)):
        n = [sum(len(r[(knob, kind)][0]) for r in per_unit) for _, kind in kinds]
        print(f"{name} unit part on the sample ({len(configs)} units, noise seed {seed}): D "
              f"{_or_none(k.dead_zone_unit_u95_deg, 2)} deg over {n[0]} values, B "
              f"{_or_none(k.backlash_unit_u95_deg, 2)} deg over {n[1]}")
    print(f"  sample: {time.monotonic() - t0:.0f} s")
    return device


def with_slope_sample(device: DeviceModel, config: TsmdConfig, plant: str,
                      params: dict[str, Any], unit_key: str, units: list[int], seed: int
                      ) -> DeviceModel:
    """The sheet with each knob's ``slope_gain_weight`` from the sheet's unit and ``units``
    (each pair printed, so the choice can be checked by hand)."""
    t0 = time.monotonic()
    pairs = []
    for p in [params, *({**params, unit_key: u} for u in units)]:
        pairs.append(sample_pairs(device, config, str(p.get(unit_key, "sheet")),
                                  functools.partial(load_plant, plant, p), seed))
        print(f"  slope sample unit {pairs[-1][0].unit}: " + "; ".join(
            f"{name} reading {q.reading:.3f} tip {q.tip:.3f}"
            for name, q in zip(("phi1", "phi2"), pairs[-1], strict=True)), flush=True)
    device, weights = with_slope_weight(device, pairs)
    for name, w in zip(("phi1", "phi2"), weights, strict=True):
        print(f"{name} slope_gain_weight on the sample ({len(pairs)} units, noise seed {seed}): "
              f"{_or_none(w, 3)}")
    print(f"  slope sample: {time.monotonic() - t0:.0f} s")
    return device


def update(args: argparse.Namespace, params: dict[str, Any], seeds: list[int]) -> int:
    """``--update FILE``: the sheet with its sample's part and/or its dead-zone loop's numbers
    (``--plateau-gap``), written to ``--out``; nothing else of it changes (checked before
    writing). With ``--stick-end`` / ``--settle-gain-check`` those choices (and the reading
    offset under the stick end) are measured first, the sample then calibrated under them, and
    the sheet is written whole."""
    seed = seeds[0] if seeds else 0
    for name in MEASURING_OPTIONS:
        if getattr(args, name) not in (None, False):
            raise DatasheetError(f"--{name.replace('_', '-')} measures a sheet anew: not with "
                                 "--update")
    if args.plant is None:
        raise DatasheetError("--update needs --plant (and --params) of the sheet's unit: the "
                             "sample is tracked on the simulated rig")
    loop = bool(args.plateau_gap)
    edges = bool(args.unit_edges)
    slope = args.slope_sample is not None
    rounded = bool(args.release_round)
    sweep = bool(args.sweep_constants)
    # nested or new fields: written whole
    whole = (args.stick_end or args.settle_gain_check or args.level_grid or args.home_hold
             or sweep)
    if (args.unit_sample is None and not loop and not whole and not edges and not slope
            and not rounded):
        raise DatasheetError("--update adds the sample's part, the loop's, the stick end, the "
                             "settle-gain check, the level grid, the hold at home, the unit's "
                             "edges, the slope weight, the rounded release or the sweep "
                             "constants: give --unit-sample, --plateau-gap, --stick-end, "
                             "--settle-gain-check, --level-grid, --home-hold, --unit-edges, "
                             "--slope-sample, --release-round or --sweep-constants")
    if args.start != DEFAULT_SHEET_START and not (sweep or loop):
        raise DatasheetError(f"--start {args.start} moves the sheet unit's sweeps and loop "
                             "only: with --update give --sweep-constants or --plateau-gap")
    source = Path(args.update)
    device = load_device_model(source)
    _same_product(source, args.plant, params)
    units = ([] if args.unit_sample is None
             else sample_units(args.unit_sample, params.get(args.unit_key)))
    config = load_config(args.config) if args.config is not None else default_sim_config()
    load_plant(args.plant, params)  # fail early, with the loader's message
    # the sweeps and the loop run on --start (calibrated: after one calibration under the
    # sheet as given); the stages that calibrate the unit start it fresh
    started = (sheet_unit_factory(args.start, lambda: load_plant(args.plant, params), device,
                                  args.seed, config)
               if args.start != DEFAULT_SHEET_START else lambda: load_plant(args.plant, params))
    if sweep:  # first: every stage after is measured under the constants it reads
        device = with_sweep_start(device, config, started, args.seed)
    if args.stick_end:
        device = with_stick_choice(device, config, args.plant, params, seeds)
    if args.settle_gain_check:
        device = with_settle_gain_check(device, config, args.plant, params, seeds)
    if args.level_grid:  # read under the sheet's own choices, as every unit is calibrated
        device = with_level_grid(device, config, lambda: load_plant(args.plant, params),
                                 args.seed)
    if args.home_hold:  # after the grid: the hold matters where branches move with the angle
        device = with_home_hold(device, config, lambda: load_plant(args.plant, params),
                                args.seed)
    updated = (with_sample(device, config, args.plant, params, args.unit_key, units, seed)
               if units else device)
    keys: tuple[str, ...] = SAMPLE_KEYS if units else ()
    what = [f"{len(units) + 1} units, fast protocol, noise seed {seed}"] if units else []
    if loop:
        updated = with_plateau_gap(updated, config, started, args.seed)
        keys += LOOP_KEYS
        what.append(f"the sheet's unit's dead-zone loop, noise seed {args.seed}, {args.start} "
                    "start")
    if rounded:  # read under the sheet's own choices, as every unit is calibrated
        updated = with_release_round(updated, config, lambda: load_plant(args.plant, params),
                                     args.seed)
        keys += ("release_round", "release_shift")
        what.append(f"the sheet's unit calibrated, tracked, noise seed {args.seed}")
    if slope:
        updated = with_slope_sample(updated, config, args.plant, params, args.unit_key,
                                    sample_units(args.slope_sample, params.get(args.unit_key)),
                                    seed)
        keys += ("slope_gain_weight",)
        what.append(f"the sheet's unit and sample {args.slope_sample} calibrated and tracked, "
                    f"noise seed {seed}")
    if edges:
        runs = seeds or [args.seed]
        updated = with_unit_edges(updated, config, lambda: load_plant(args.plant, params), runs)
        keys += UNIT_EDGE_KEYS
        what.append(f"the sheet's unit calibrated, noise seeds {','.join(map(str, runs))}")
    command = (f"tsmd datasheet --update {source} --plant {args.plant} --params "
               f"'{json.dumps(params)}' --unit-key {args.unit_key}"
               + (f" --unit-sample {args.unit_sample}" if units else "")
               + (" --plateau-gap" if loop else "")
               + (f" --start {args.start}" if loop and not sweep else "")
               + (" --unit-edges" if edges else "")
               + (f" --slope-sample {args.slope_sample}" if slope else "")
               + (f" --release-round --seed {args.seed}" if rounded else "")
               + (" --stick-end" if args.stick_end else "")
               + (" --settle-gain-check" if args.settle_gain_check else "")
               + (f" --level-grid --seed {args.seed}" if args.level_grid else "")
               + (f" --home-hold --seed {args.seed}" if args.home_hold else "")
               + (f" --sweep-constants --start {args.start} --seed {args.seed}" if sweep
                  else "")
               + (f" --rule-seeds {','.join(map(str, seeds))}"
                  if seeds and (args.stick_end or args.settle_gain_check or edges) else "")
               + " --out FILE")
    if whole:
        fields = ((["backlash_stick_end", "reading_offset"] if args.stick_end else [])
                  + (["settle_gain_read"] if args.settle_gain_check else [])
                  + (["loaded_level_grid"] if args.level_grid else [])
                  + (["hold_at_home"] if args.home_hold else [])
                  + ([f"the sweep constants ({args.start} start)"] if sweep else [])
                  + list(keys))
        save_device_model(updated, args.out, source_header(source) + (
            f"\n{', '.join(fields)} measured by tsmd {__version__} (no other field changed):"
            f"\n  {command}"))
        print(f"tsmd datasheet: wrote {args.out} ({source} with {', '.join(fields)})")
        return 0
    save_device_fields(source, updated, keys, args.out,
                       f"{', '.join(keys)} added by tsmd {__version__}:\n  {command}\n"
                       f"  ({'; '.join(what)}; no other field changed)")
    print(f"tsmd datasheet: wrote {args.out} ({source} with {', '.join(keys)})")
    return 0


def _same_product(source: Path, plant: str, params: dict[str, Any]) -> None:
    """Refuse a sample of another product than the one the sheet's header names (a header
    naming none, e.g. a hand-written one, is taken at the caller's word)."""
    head = "".join(line for line in source.read_text(encoding="utf-8").splitlines(True)
                   if line.startswith("#"))
    m = re.search(r"plant (\S+) with (\{[^}]*\})", head)
    if m is None:
        print(f"warning: {source}'s header names no plant: the sample is taken as units of "
              f"{plant} with {json.dumps(params)}")
        return
    if m[1] != plant or json.loads(m[2]) != params:
        raise DatasheetError(f"{source} was measured on {m[1]} with {m[2]}, not {plant} with "
                             f"{json.dumps(params)}: its sample must be units of its product")


def _or_none(value: float | None, decimals: int) -> str:
    return "none" if value is None or not math.isfinite(value) else f"{value:.{decimals}f}"
