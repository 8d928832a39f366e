"""`tsmd datasheet --update FILE --play-step`: the play-step choice made on an existing sheet's
unit (:mod:`tsmd.datasheet_play_step`) and, where a knob takes the step, the product's reading
offset measured again under it; every other field as it was (session 24)."""

from __future__ import annotations

import argparse
import dataclasses
import json
import time
from pathlib import Path
from typing import Any

from simrig.plant import load_plant
from tsmd import __version__
from tsmd.calibration.protocol import fast_protocol
from tsmd.config import TsmdConfig, default_sim_config, load_config
from tsmd.datasheet import DatasheetError
from tsmd.datasheet_offset import with_reading_offset, without_offset
from tsmd.datasheet_play_step import PlayStepScore, play_step_scores, with_play_step
from tsmd.datasheet_rule import sheet_truth
from tsmd.profile import DeviceModel, load_device_model, save_device_model
from tsmd.tracked_calibration import play_protocol, truth_sweeps


def choose_play_step(device: DeviceModel, unit: TsmdConfig, seeds: list[int]
                     ) -> tuple[DeviceModel, tuple[PlayStepScore, PlayStepScore]]:
    """The sheet with each knob's play-step choice from its unit's fast calibrations (one per
    noise seed) and, where a knob took it, the reading offset measured again under it."""
    sweeps = truth_sweeps(unit)
    truth = sheet_truth(unit, sweeps)
    plain = dataclasses.replace(without_offset(device), knobs=tuple(
        dataclasses.replace(k, backlash_play_step=None) for k in device.knobs))  # type: ignore[arg-type]
    runs = [play_protocol(unit, plain, fast_protocol(), seed) for seed in seeds]
    scores = play_step_scores(runs, plain, truth)
    chosen = with_play_step(device, scores)
    if any(s.chosen for s in scores):
        chosen, _ = with_reading_offset(chosen, unit, truth, seeds, sweeps)
    return chosen, scores


def play_step_update(args: argparse.Namespace, params: dict[str, Any], seeds: list[int]) -> int:
    """``--update FILE --play-step``: write the sheet with its play-step choice to ``--out``."""
    if args.plant is None or not seeds:
        raise DatasheetError("--play-step needs --plant (and --params) of the sheet's unit and "
                             "rule seeds: the unit is calibrated and tracked on the simulated rig")
    source = Path(args.update)
    device = load_device_model(source)
    config = load_config(args.config) if args.config is not None else default_sim_config()
    load_plant(args.plant, params)  # fail early, with the loader's message
    unit = config.replace(sim=dataclasses.replace(config.sim, plant=args.plant, params=params))
    t0 = time.monotonic()
    chosen, scores = choose_play_step(device, unit, seeds)
    for name, s, k in zip(("phi1", "phi2"), scores, chosen.knobs, strict=True):
        print(f"{name} play step on the sheet's unit, fast protocol, noise seeds "
              f"{','.join(map(str, seeds))}: {s.text()}")
        if s.chosen and k.reading_offset is not None:
            print(f"  {name} reading offset under the step: " + "; ".join(
                f"{g_name} " + " ".join(f"{m:+.2f}+-{u:.2f}" for m, u in
                                        zip(g.mean_deg, g.u95_deg, strict=True))
                for g_name, g in k.reading_offset.grids))
    print(f"  play-step choice: {time.monotonic() - t0:.0f} s")
    head = [line[2:] if line.startswith("# ") else line[1:]
            for line in source.read_text(encoding="utf-8").splitlines() if line.startswith("#")]
    command = (f"tsmd datasheet --update {source.name} --play-step --plant {args.plant} "
               f"--params '{json.dumps(params)}' --rule-seeds {','.join(map(str, seeds))} "
               "--out FILE")
    head.append(f"backlash_play_step chosen by tsmd {__version__} ({command}): " + "; ".join(
        f"{name} {s.text()}" for name, s in zip(("phi1", "phi2"), scores, strict=True))
        + ("; the reading offset measured again under it" if any(s.chosen for s in scores)
           else "; nothing else changed"))
    save_device_model(chosen, args.out, "\n".join(head))
    print(f"tsmd datasheet: wrote {args.out} ({source} with its play-step choice)")
    return 0
