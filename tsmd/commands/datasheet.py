"""`tsmd datasheet`: measure a device's data sheet and write the device YAML.

``--plant module:factory [--params JSON]``: on the simulated rig, tip tracked by the simulated
EM tracker. ``--from-recording FILE...``: from a tracked real unit, one +-90 deg sweep recording
per knob (the recording format of docs/recording-format.md, with tip columns).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from simrig.plant import Plant, load_plant
from tsmd import __version__
from tsmd.commands.datasheet_args import add_arguments
from tsmd.commands.datasheet_measure import (
    or_none,
    with_bend,
    with_coupling,
    with_release_end_offset,
    with_shape_grid,
    with_tip_backlash_gain,
)
from tsmd.commands.datasheet_sample import sample_units, with_sample
from tsmd.commands.datasheet_stick import with_settle_gain_check, with_stick_choice
from tsmd.commands.datasheet_update import update
from tsmd.config import DEFAULT_CONFIG_PATH, TsmdConfig, default_sim_config, load_config
from tsmd.datasheet import (
    ANALYSED_CYCLES,
    CONDITIONING_CYCLES,
    RELEASE_READ_CYCLES,
    SWEEP_AMPLITUDE_DEG,
    SWEEP_HZ,
    DatasheetError,
    KnobConstants,
    device_model,
    knob_constants,
    measure_device_constants,
    readable,
    swept_knob,
)
from tsmd.datasheet_edge_curve import choose_edge_curve, with_edge_curve
from tsmd.datasheet_edge_level import with_edge_level_share
from tsmd.datasheet_flat_heights import with_flat_heights
from tsmd.datasheet_home_hold import with_home_hold
from tsmd.datasheet_level_grid import with_level_grid
from tsmd.datasheet_offset import with_reading_offset
from tsmd.datasheet_plateau_gap import with_plateau_gap
from tsmd.datasheet_ratio_gain import with_ratio_gain
from tsmd.datasheet_recovery import recovery_where_chosen, with_recovery_constants
from tsmd.datasheet_release_round import with_release_round
from tsmd.datasheet_reversal_release import with_release_end
from tsmd.datasheet_rule import (
    choose_knee,
    choose_rules,
    rule_scores,
    sheet_truth,
)
from tsmd.datasheet_rule_settled import rule_text
from tsmd.datasheet_shape_choice import with_shape_choice
from tsmd.datasheet_start import DEFAULT_SHEET_START, sheet_unit_factory
from tsmd.datasheet_unit_edges import with_unit_edges
from tsmd.profile import DeviceModel, save_device_model
from tsmd.profile.reading_offset import ReadingOffset
from tsmd.profile.sheet_schema import OPTIONAL_KNOB_RANGES
from tsmd.recording import read_recording
from tsmd.tracked_calibration import truth_sweeps


def _params(text: str | None) -> dict[str, Any]:
    if text is None:
        return {}
    try:
        params = json.loads(text)
    except json.JSONDecodeError as exc:
        raise DatasheetError(f"--params: not JSON: {exc.msg}") from None
    if not isinstance(params, dict):
        raise DatasheetError("--params: must be a JSON object of plant parameters")
    return params


def _from_recordings(paths: list[str], ripple_period_deg: float | None,
                     edge_rise: bool = False) -> list[KnobConstants]:
    by_knob: dict[int, KnobConstants] = {}
    for path in paths:
        rec = read_recording(path)
        knob = swept_knob(rec)
        if knob in by_knob:
            raise DatasheetError(f"{path}: a second sweep of knob {knob + 1}; give one per knob")
        try:
            by_knob[knob] = knob_constants(rec, knob, ripple_period_deg=ripple_period_deg,
                                           edge_rise=edge_rise)
        except DatasheetError as exc:
            raise DatasheetError(f"{path}: {exc}") from None
    missing = [k + 1 for k in (0, 1) if k not in by_knob]
    if missing:
        raise DatasheetError(f"no sweep of knob {missing[0]} among the recordings")
    return [by_knob[0], by_knob[1]]


def _ripple_period(value: float | None) -> float | None:
    low, high, _ = OPTIONAL_KNOB_RANGES["torque_ripple_period_deg"]
    if value is not None and not low <= value <= high:
        raise DatasheetError(f"--torque-ripple-period-deg {value:g}: outside [{low:g}, {high:g}] "
                             "deg")
    return value


def _rule_seeds(text: str) -> list[int]:
    if text.strip().lower() == "none":
        return []
    try:
        seeds = [int(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise DatasheetError("--rule-seeds: not a comma-separated list of integers or 'none': "
                             f"{text!r}") from None
    if not seeds:
        raise DatasheetError("--rule-seeds: give at least one seed, or 'none'")
    return seeds


def _choose_rule(device: DeviceModel, config: TsmdConfig, plant: str,
                 params: dict[str, Any], seeds: list[int], recovery: bool = False
                 ) -> DeviceModel:
    """The sheet with each knob's backlash rule, chosen on its own unit's calibrations
    (``recovery``: "recovery" offered too, its constants measured first), each knob's
    curved-hinge check (:mod:`tsmd.datasheet_edge_curve`) and the product's reading offset
    measured with both."""
    unit = config.replace(sim=dataclasses.replace(config.sim, plant=plant, params=params))
    sweeps = truth_sweeps(unit)
    truth = sheet_truth(unit, sweeps)
    if recovery:
        t0 = time.monotonic()
        device, _ = with_recovery_constants(device, unit, truth, seeds)
        for name, k in zip(("phi1", "phi2"), device.knobs, strict=True):
            print(f"{name} recovery rule on the sheet's unit, fast protocol, noise seeds "
                  f"{','.join(map(str, seeds))}: lag {or_none(k.backlash_recovery_lag_deg, 2)} "
                  f"deg, bend gain {or_none(k.backlash_bend_gain, 3)}")
        print(f"  recovery constants: {time.monotonic() - t0:.0f} s")
    t0 = time.monotonic()
    scores = rule_scores(unit, device, seeds, truth)
    chosen, knee = choose_knee(unit, choose_rules(device, scores), scores, truth, seeds)
    chosen = recovery_where_chosen(chosen)
    for knob, name in enumerate(("phi1", "phi2")):
        mine = "; ".join(s.text() for s in scores if s.knob == knob)
        k = chosen.knobs[knob]
        print(f"{name} backlash rule on the sheet's unit, fast protocol, noise seeds "
              f"{','.join(map(str, seeds))}: {mine}; with the knee: {knee[knob].text()} -> "
              f"{rule_text(k)}, knee {'on' if k.backlash_knee else 'off'}")
    print(f"  rule choice: {time.monotonic() - t0:.0f} s")
    t0 = time.monotonic()
    before = chosen
    chosen, curve, curve_runs = choose_edge_curve(unit, before, truth, seeds)
    for name, c in zip(("phi1", "phi2"), curve, strict=True):
        print(f"{name} curved-hinge check on the sheet's unit, fast protocol: {c.text()}")
    print(f"  edge-curve choice: {time.monotonic() - t0:.0f} s")
    t0 = time.monotonic()
    # where no knob took the check, the edge-curve runs are the reading offset's own
    made = (with_edge_curve(before, (False, False)), curve_runs)
    chosen, _ = with_reading_offset(chosen, unit, truth, seeds, sweeps, made)
    for name, k in zip(("phi1", "phi2"), chosen.knobs, strict=True):
        print(f"{name} reading offset (current minus tip, deg, at the other knob's "
              f"{_angles(k.reading_offset)}): {_offsets(k.reading_offset)}")
    print(f"  reading offset: {time.monotonic() - t0:.0f} s")
    return chosen












def _angles(offset: ReadingOffset | None) -> str:
    return "none" if offset is None else "/".join(f"{a:+.0f}" for a in offset.other_knob_deg)


def _offsets(offset: ReadingOffset | None) -> str:
    if offset is None:
        return "none"
    return "; ".join(f"{name} " + " ".join(f"{m:+.2f}+-{u:.2f}" for m, u in
                                           zip(g.mean_deg, g.u95_deg, strict=True))
                     for name, g in offset.grids)






def _sheet(args: argparse.Namespace, constants: list[KnobConstants], config: TsmdConfig,
           ripple: float | None) -> DeviceModel:
    """The sheet its sweep constants give, with the handle's design constants and readable."""
    device = device_model(args.device_model, constants, config, args.description,
                          loaded_shape=args.loaded_shape or args.choose_loaded_shape)
    if ripple is not None:
        phi1, phi2 = (dataclasses.replace(k, torque_ripple_period_deg=ripple)
                      for k in device.knobs)
        device = dataclasses.replace(device, knobs=(phi1, phi2))
    if args.edge_rise:
        phi1, phi2 = (dataclasses.replace(k, edge_rise=True) for k in device.knobs)
        device = dataclasses.replace(device, knobs=(phi1, phi2))
    device, dropped = readable(device)
    for line in dropped:
        print(f"warning: {line}")
    return device


def main(args: argparse.Namespace) -> int:
    if args.params is not None and args.plant is None:
        raise DatasheetError("--params goes with --plant")
    if args.choose_loaded_shape and (args.plant is None or args.loaded_shape):
        raise DatasheetError("--choose-loaded-shape goes with --plant and without --loaded-shape "
                             "(which keeps the templates and their grid unchosen)")
    if args.bend_slopes and not args.bend_relation:
        raise DatasheetError("--bend-slopes goes with --bend-relation")
    if args.bend_relation and args.plant is None:
        raise DatasheetError("--bend-relation goes with --plant (the unit is calibrated bent on "
                             "the simulated rig)")
    if args.flat_sample is not None and not (args.update is not None and args.flat_heights):
        raise DatasheetError("--flat-sample goes with --update and --flat-heights (the flats "
                             "are judged on the sample under a measured sheet)")
    seeds = _rule_seeds(args.rule_seeds)
    if args.sweep_constants and args.update is None:
        raise DatasheetError("--sweep-constants goes with --update (a full measurement sweeps "
                             "the unit anyway; --start says on which state)")
    if args.start != DEFAULT_SHEET_START and args.plant is None:
        raise DatasheetError(f"--start {args.start} goes with --plant (the unit is calibrated "
                             "on the simulated rig before its sweeps)")
    if args.update is not None:
        return update(args, _params(args.params), seeds)
    if args.slope_sample is not None:
        raise DatasheetError("--slope-sample goes with --update (the weight is added to a "
                             "measured sheet, its sample calibrated under it)")
    if args.device_model is None:
        raise DatasheetError("--device-model is required (or --update FILE)")
    params = _params(args.params)
    ripple = _ripple_period(args.torque_ripple_period_deg)
    sample = (sample_units(args.unit_sample, params.get(args.unit_key))
              if args.unit_sample is not None else [])
    if sample and args.plant is None:
        raise DatasheetError("--unit-sample goes with --plant (the sample is tracked on the "
                             "simulated rig)")
    if args.recovery_rule and (args.plant is None or not seeds):
        raise DatasheetError("--recovery-rule goes with --plant and rule seeds (the rule is "
                             "offered in the rule choice on the simulated rig)")
    if args.plant is not None:
        config = load_config(args.config) if args.config is not None else default_sim_config()
        load_plant(args.plant, params)  # fail early, with the loader's message

        def factory() -> Plant:
            return load_plant(args.plant, params)
        sweeps: Callable[[], Any] = factory  # the sheet unit's sweeps; see --start

        constants = measure_device_constants(factory, args.seed, config, ripple, args.edge_rise)
        source = (f"the simulated rig, plant {args.plant} with {json.dumps(params)}, seed "
                  f"{args.seed}, {RELEASE_READ_CYCLES:g} cycles per knob (whole passes: the "
                  f"first {ANALYSED_CYCLES:g})")
    else:
        constants = _from_recordings(args.from_recording, ripple, args.edge_rise)
        config = load_config(args.config if args.config is not None else DEFAULT_CONFIG_PATH)
        source = "recordings " + ", ".join(Path(p).name for p in args.from_recording)
    device = _sheet(args, constants, config, ripple)
    if ripple is not None:
        source += f"; the handle's torque ripple period {ripple:g} deg given (a design constant)"
    if args.edge_rise:
        source += "; edges read where the current starts to rise (the product's reader)"
    if args.plant is not None and args.start != DEFAULT_SHEET_START:
        # the unit calibrated under the sheet its fresh sweeps give, then swept again
        sweeps = sheet_unit_factory(args.start, factory, device, args.seed, config)
        constants = measure_device_constants(sweeps, args.seed, config, ripple, args.edge_rise)
        device = _sheet(args, constants, config, ripple)
        source += (f"; swept after a calibration under the sheet its fresh sweeps gave (start "
                   f"{args.start}, the stages that calibrate the unit start it fresh)")
    if args.plant is not None:
        device = with_coupling(device, config, sweeps, args.seed)
    if args.plant is not None and args.tip_backlash_gain:
        device = with_tip_backlash_gain(device, config, sweeps, args.seed)
    if args.plant is not None and args.tip_line_backlash_gain:
        device = with_tip_backlash_gain(device, config, sweeps, args.seed, by="lines")
    if args.plant is not None and args.loaded_shape:
        device = with_shape_grid(device, config, sweeps, args.seed)
    # the stages below calibrate the unit themselves: each starts it fresh, as every unit's
    # calibration starts
    if args.plant is not None and seeds:
        device = _choose_rule(device, config, args.plant, params, seeds, args.recovery_rule)
    if args.plant is not None and args.stick_end:  # after the rule: its offset measured again
        device = with_stick_choice(device, config, args.plant, params, seeds)
    if args.plant is not None and args.settle_gain_check:
        device = with_settle_gain_check(device, config, args.plant, params, seeds)
    if args.plant is not None and args.choose_loaded_shape:  # under the sheet's rules
        device = with_shape_choice(device, config, factory, args.seed)
    if args.plant is not None and not args.no_ratio_gain:
        device = with_ratio_gain(device, config, factory,
                                 [round(c.release_omega, 2) for c in constants], args.seed,
                                 args.ratio_gain_none)
    if args.plant is not None and args.bend_relation:
        device = with_bend(device, config, factory, args.bend_slopes)
    if args.plant is not None and args.release_end_offset:
        device = with_release_end_offset(device, config, factory, args.seed)
    if args.plant is not None and args.release_round:
        device = with_release_round(device, config, factory, args.seed)
    if args.plant is not None and args.edge_level_share:  # the level grid reads what is left
        device = with_edge_level_share(device, config, factory, args.seed)
    if args.plant is not None and args.release_end_shape:
        device = with_release_end(device, config, factory, args.seed)
    if args.plant is not None and args.level_grid:
        device = with_level_grid(device, config, factory, args.seed)
    if args.plant is not None and args.plateau_gap:  # a tracked loop: on the sweeps' start
        device = with_plateau_gap(device, config, sweeps, args.seed)
    if args.plant is not None and args.unit_edges:  # under the sheet's rules, as a unit
        device = with_unit_edges(device, config, factory, seeds or [args.seed],
                                 args.unit_edges_move)
    if args.plant is not None and args.flat_heights:  # after the edges the heights go through
        device = with_flat_heights(device, config, factory, args.seed)
    if args.plant is not None and args.home_hold:  # under the sheet as every unit is calibrated
        device = with_home_hold(device, config, factory, args.seed)
    if args.plant is not None and sample:
        device = with_sample(device, config, args.plant, params, args.unit_key, sample,
                             seeds[0] if seeds else 0)
    if args.plant is not None:  # the gains read since may move the ratio out of its range
        device, dropped = readable(device)
        for line in dropped:
            print(f"warning: {line}")
    comment = (f"Data sheet of {args.device_model}, measured by tsmd {__version__} "
               f"(tsmd datasheet) on {source}:\n"
               f"each knob swept +-{SWEEP_AMPLITUDE_DEG:g} deg at {SWEEP_HZ:g} Hz, other knob "
               f"at 0 deg (and held at +-90 deg for the planes' coupling), analysed after "
               f"{CONDITIONING_CYCLES:g} conditioning cycle(s); tip "
               f"from the tracker.\nLimits: limits.* of the configuration.")
    save_device_model(device, args.out, comment)
    for name, c in zip(("phi1", "phi2"), constants, strict=True):
        print(f"{name}: omega {c.omega:.2f}, release_omega {c.release_omega:.2f}, reference "
              f"tip {c.reference_pos.tip_deg:.2f}/{c.reference_neg.tip_deg:.2f} deg, backlash "
              f"{c.reference_backlash_pos_deg:.2f}/{c.reference_backlash_neg_deg:.2f} deg, "
              f"dead-zone offset {c.dead_zone_offset_deg:.2f} deg, release share "
              f"{or_none(c.backlash_settle_fraction, 3)} and slope ratio "
              f"{or_none(c.backlash_release_slope_ratio, 4)}, swing "
              f"{or_none(c.release_swing_A, 4)} A, settle lag {or_none(c.settle_lag_deg, 2)} "
              f"deg, line share {or_none(c.release_line_share, 4)}, local share "
              f"{or_none(c.release_local_share, 4)} over "
              f"{c.release_reversals} reversals")
        for side, shape in (("+", c.loaded_shape_pos), ("-", c.loaded_shape_neg)):
            # tip travel past the plateau over knob travel past the edge
            if (args.loaded_shape or args.choose_loaded_shape) and shape is not None:
                print(f"  loaded shape {side}: T(u)/u " + " ".join(
                    f"{u:g}:{t / u:.3f}" for u, t in zip(shape.travel_deg[1:],
                                                         shape.shaped_deg[1:], strict=True)))
    print(f"tsmd datasheet: wrote {args.out}")
    return 0


__all__ = ["add_arguments", "main"]
