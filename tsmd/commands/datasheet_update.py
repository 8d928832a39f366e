"""`tsmd datasheet --update FILE`: stages added to an existing sheet, each measured on the
sheet's unit under the sheet as it stands, with nothing else of it changed.

A stage is one row of :data:`UPDATE_STAGES`: the option that asks for it, the fields it writes,
how it measures, and the words the new header records so the file says how to measure it again.
Rows run in the table's order: the choices every unit is calibrated under (stick end, settle
check, level grid, hold at home) first, then what is read under them. A stage whose fields are
nested or new writes the sheet whole; the others replace only their own lines.
"""

from __future__ import annotations

import argparse
import functools
import json
import re
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from simrig.plant import Plant, load_plant
from tsmd import __version__
from tsmd.commands.datasheet_sample import sample_units, with_sample, with_slope_sample
from tsmd.commands.datasheet_stick import (
    source_header,
    with_settle_gain_check,
    with_stick_choice,
)
from tsmd.commands.datasheet_sweep import with_sweep_start
from tsmd.config import TsmdConfig, default_sim_config, load_config
from tsmd.datasheet import DatasheetError
from tsmd.datasheet_flat_heights import FLAT_HEIGHT_KEYS, with_flat_heights
from tsmd.datasheet_home_hold import with_home_hold
from tsmd.datasheet_level_grid import with_level_grid
from tsmd.datasheet_plateau_gap import LOOP_KEYS, with_plateau_gap
from tsmd.datasheet_release_round import with_release_round
from tsmd.datasheet_sample import SAMPLE_KEYS
from tsmd.datasheet_start import DEFAULT_SHEET_START, sheet_unit_factory
from tsmd.datasheet_unit_edges import UNIT_EDGE_KEYS, with_unit_edges
from tsmd.profile import DeviceModel, load_device_model, save_device_fields, save_device_model

MEASURING_OPTIONS = ("from_recording", "device_model", "loaded_shape", "tip_backlash_gain",
                     "tip_line_backlash_gain", "release_end_offset", "recovery_rule",
                     "bend_relation")
"""Options that measure a sheet anew: not with ``--update``."""


@dataclass(frozen=True)
class StageRun:
    """One ``--update`` call as its stages see it."""

    args: argparse.Namespace
    params: dict[str, Any]
    """The plant factory's parameters of the sheet's unit."""
    config: TsmdConfig
    rule_seeds: list[int]
    """``--rule-seeds``: the noise seeds a choice must hold on."""
    sample: list[int]
    """``--unit-sample``'s units (empty without it)."""
    slope_sample: list[int]
    """``--slope-sample``'s units (empty without it)."""
    flat_sample: list[int]
    """``--flat-sample``'s units: they judge the flats instead of the sheet's unit."""
    started: Callable[[], Plant] | None = None
    """The sheet's unit at ``--start`` (calibrated: after one calibration under the sheet as
    given) for the stages that play on it; None: fresh, as :meth:`plant`."""

    @property
    def sample_seed(self) -> int:
        """The sample's calibrations run on the first rule seed (0 without any)."""
        return self.rule_seeds[0] if self.rule_seeds else 0

    def plant(self) -> Plant:
        """A fresh plant of the sheet's unit (each stage's runs start from one)."""
        return load_plant(self.args.plant, self.params)

    def start_plant(self) -> Plant:
        """The sheet's unit at ``--start``, for the sweeps and the dead-zone loop (the stages
        that calibrate the unit themselves start it fresh)."""
        return self.started() if self.started is not None else self.plant()

    def unit_plants(self, units: list[int]) -> list[tuple[str, Callable[[], Plant]]]:
        """Each unit of the product with a factory of its fresh plant."""
        return [(str(u), functools.partial(load_plant, self.args.plant,
                                           {**self.params, self.args.unit_key: u}))
                for u in units]


@dataclass(frozen=True)
class UpdateStage:
    """One stage ``--update`` can add to a sheet."""

    option: str
    """The parsed option that asks for it (an ``argparse`` dest)."""
    name: str
    """What it adds, for the message when no stage is asked for."""
    fields: tuple[str, ...]
    """The knob fields it writes."""
    whole: bool
    """Nested or new fields: the sheet is written whole (its other fields as they were)."""
    measure: Callable[[DeviceModel, StageRun], DeviceModel]
    words: Callable[[StageRun], str]
    """Its words on the command line the header records."""
    what: Callable[[StageRun], str]
    """What it ran, for the header of a sheet written field by field."""
    uses_rule_seeds: bool = False
    plays_start: bool = False
    """It plays on the unit at ``--start`` (the others start it fresh)."""


def _no_words(run: StageRun) -> str:
    return ""


UPDATE_STAGES: tuple[UpdateStage, ...] = (
    UpdateStage(  # first: every stage after is measured under the constants it reads
        "sweep_constants", "the sweep constants", ("sweep constants",), True,
        lambda d, r: with_sweep_start(d, r.config, r.start_plant, r.args.seed),
        lambda r: f" --sweep-constants --start {r.args.start} --seed {r.args.seed}", _no_words,
        plays_start=True),
    UpdateStage(
        "stick_end", "the stick end", ("backlash_stick_end", "reading_offset"), True,
        lambda d, r: with_stick_choice(d, r.config, r.args.plant, r.params, r.rule_seeds),
        lambda r: " --stick-end", _no_words, uses_rule_seeds=True),
    UpdateStage(
        "settle_gain_check", "the settle-gain check", ("settle_gain_read",), True,
        lambda d, r: with_settle_gain_check(d, r.config, r.args.plant, r.params, r.rule_seeds),
        lambda r: " --settle-gain-check", _no_words, uses_rule_seeds=True),
    UpdateStage(  # read under the sheet's own choices, as every unit is calibrated
        "level_grid", "the level grid", ("loaded_level_grid",), True,
        lambda d, r: with_level_grid(d, r.config, r.plant, r.args.seed),
        lambda r: f" --level-grid --seed {r.args.seed}", _no_words),
    UpdateStage(  # after the grid: the hold matters where branches move with the angle
        "home_hold", "the hold at home", ("hold_at_home",), True,
        lambda d, r: with_home_hold(d, r.config, r.plant, r.args.seed),
        lambda r: f" --home-hold --seed {r.args.seed}", _no_words),
    UpdateStage(
        "unit_sample", "the sample's part", SAMPLE_KEYS, False,
        lambda d, r: with_sample(d, r.config, r.args.plant, r.params, r.args.unit_key, r.sample,
                                 r.sample_seed),
        lambda r: f" --unit-sample {r.args.unit_sample}",
        lambda r: f"{len(r.sample) + 1} units, fast protocol, noise seed {r.sample_seed}"),
    UpdateStage(
        "plateau_gap", "the dead-zone loop's numbers", LOOP_KEYS, False,
        lambda d, r: with_plateau_gap(d, r.config, r.start_plant, r.args.seed),
        lambda r: " --plateau-gap" + ("" if r.args.sweep_constants else
                                      f" --start {r.args.start}"),
        lambda r: (f"the sheet's unit's dead-zone loop, noise seed {r.args.seed}, "
                   f"{r.args.start} start"),
        plays_start=True),
    UpdateStage(  # read under the sheet's own choices, as every unit is calibrated
        "release_round", "the rounded release", ("release_round", "release_shift"), False,
        lambda d, r: with_release_round(d, r.config, r.plant, r.args.seed),
        lambda r: f" --release-round --seed {r.args.seed}",
        lambda r: f"the sheet's unit calibrated, tracked, noise seed {r.args.seed}"),
    UpdateStage(
        "slope_sample", "the slope weight", ("slope_gain_weight",), False,
        lambda d, r: with_slope_sample(d, r.config, r.args.plant, r.params, r.args.unit_key,
                                       r.slope_sample, r.sample_seed),
        lambda r: f" --slope-sample {r.args.slope_sample}",
        lambda r: (f"the sheet's unit and sample {r.args.slope_sample} calibrated and "
                   f"tracked, noise seed {r.sample_seed}")),
    UpdateStage(
        "unit_edges", "the unit's edges", UNIT_EDGE_KEYS, False,
        lambda d, r: with_unit_edges(d, r.config, r.plant, r.rule_seeds or [r.args.seed],
                                     r.args.unit_edges_move),
        lambda r: " --unit-edges" + (" --unit-edges-move" if r.args.unit_edges_move else ""),
        lambda r: ("the sheet's unit calibrated"
                   + (" and its tip swept fresh and calibrated" if r.args.unit_edges_move else "")
                   + ", noise seeds " + ",".join(map(str, r.rule_seeds or [r.args.seed]))),
        uses_rule_seeds=True),
    UpdateStage(  # after the edges: measured against the heights drawn through them
        "flat_heights", "the flats", FLAT_HEIGHT_KEYS, False,
        lambda d, r: with_flat_heights(d, r.config, r.plant, r.args.seed,
                                       r.unit_plants(r.flat_sample)),
        lambda r: (f" --flat-heights --seed {r.args.seed}"
                   + (f" --flat-sample {r.args.flat_sample}" if r.flat_sample else "")),
        lambda r: (f"the sheet's unit calibrated, tracked, judged on "
                   f"{'units ' + r.args.flat_sample if r.flat_sample else 'it'}, noise seed "
                   f"{r.args.seed}")),
)
"""Every stage ``--update`` knows, in the order they run."""


def _option(stage: UpdateStage) -> str:
    return "--" + stage.option.replace("_", "-")


def asked_stages(args: argparse.Namespace) -> list[UpdateStage]:
    """The stages the options ask for, in the table's order (refused when none is)."""
    stages = [s for s in UPDATE_STAGES if getattr(args, s.option) not in (None, False)]
    if not stages:
        names = [s.name for s in UPDATE_STAGES]
        raise DatasheetError(f"--update adds {', '.join(names[:-1])} or {names[-1]}: give "
                             + ", ".join(_option(s) for s in UPDATE_STAGES[:-1])
                             + f" or {_option(UPDATE_STAGES[-1])}")
    return stages


def update(args: argparse.Namespace, params: dict[str, Any], seeds: list[int]) -> int:
    """``--update FILE``: the asked stages measured on the sheet's unit, in order, each under
    the sheet as the stages before left it, written to ``--out``; nothing else of the sheet
    changes (checked before writing)."""
    for name in MEASURING_OPTIONS:
        if getattr(args, name) not in (None, False):
            raise DatasheetError(f"--{name.replace('_', '-')} measures a sheet anew: not with "
                                 "--update")
    if args.plant is None:
        raise DatasheetError("--update needs --plant (and --params) of the sheet's unit: the "
                             "sample is tracked on the simulated rig")
    stages = asked_stages(args)
    if args.start != DEFAULT_SHEET_START and not any(s.plays_start for s in stages):
        raise DatasheetError(f"--start {args.start} moves only the stages that play on the "
                             "sheet's unit: with --update give "
                             + " or ".join(_option(s) for s in UPDATE_STAGES if s.plays_start))
    source = Path(args.update)
    device = load_device_model(source)
    _same_product(source, args.plant, params)
    own = params.get(args.unit_key)
    run = StageRun(
        args, params,
        load_config(args.config) if args.config is not None else default_sim_config(), seeds,
        [] if args.unit_sample is None else sample_units(args.unit_sample, own),
        [] if args.slope_sample is None else sample_units(args.slope_sample, own),
        [] if args.flat_sample is None else sample_units(args.flat_sample, own))
    load_plant(args.plant, params)  # fail early, with the loader's message
    if args.start != DEFAULT_SHEET_START:  # calibrated under the sheet as given
        run = replace(run, started=sheet_unit_factory(args.start, run.plant, device, args.seed,
                                                       run.config))
    for stage in stages:
        device = stage.measure(device, run)
    command = (f"tsmd datasheet --update {source} --plant {args.plant} --params "
               f"'{json.dumps(params)}' --unit-key {args.unit_key}"
               + "".join(s.words(run) for s in stages)
               + (f" --rule-seeds {','.join(map(str, seeds))}"
                  if seeds and any(s.uses_rule_seeds for s in stages) else "")
               + " --out FILE")
    fields = tuple(f for s in stages for f in s.fields)
    if any(s.whole for s in stages):
        save_device_model(device, args.out, source_header(source) + (
            f"\n{', '.join(fields)} measured by tsmd {__version__} (no other field changed):"
            f"\n  {command}"))
    else:
        save_device_fields(source, device, fields, args.out,
                           f"{', '.join(fields)} added by tsmd {__version__}:\n  {command}\n"
                           f"  ({'; '.join(s.what(run) for s in stages)}; no other field "
                           "changed)")
    print(f"tsmd datasheet: wrote {args.out} ({source} with {', '.join(fields)})")
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
