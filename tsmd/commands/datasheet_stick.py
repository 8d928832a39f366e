"""`tsmd datasheet --stick-end` and ``--settle-gain-check``: the stick phase's end chosen on the
sheet's unit (:mod:`tsmd.datasheet_stick_end`) and the settle-gain reading checked there
(:mod:`tsmd.datasheet_settle_gain`), printed; on a sheet being measured or, with ``--update``,
on an existing one (then written whole: the reading offset measured again is a nested field)."""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any

from tsmd.calibration.protocol import paper_protocol
from tsmd.config import TsmdConfig
from tsmd.datasheet import DatasheetError
from tsmd.datasheet_rule import sheet_truth
from tsmd.datasheet_settle_gain import with_settle_check
from tsmd.datasheet_stick_end import choose_stick_end
from tsmd.profile import DeviceModel
from tsmd.tracked_calibration import play_protocol, truth_sweeps


def with_stick_choice(device: DeviceModel, config: TsmdConfig, plant: str,
                      params: dict[str, Any], seeds: list[int]) -> DeviceModel:
    """The sheet with each knob's stick-end choice on its own unit, the choice printed."""
    if not seeds:
        raise DatasheetError("--stick-end needs rule seeds (the sheet's unit is calibrated once "
                             "per seed with and without it)")
    t0 = time.monotonic()
    unit = config.replace(sim=dataclasses.replace(config.sim, plant=plant, params=params))
    sweeps = truth_sweeps(unit)
    chosen, choices = choose_stick_end(unit, device, sheet_truth(unit, sweeps), seeds, sweeps)
    for name, c in zip(("phi1", "phi2"), choices, strict=True):
        print(f"{name} stick end on the sheet's unit, fast protocol, noise seeds "
              f"{','.join(map(str, seeds))}: {c.text()}")
    print(f"  stick-end choice: {time.monotonic() - t0:.0f} s")
    return chosen


def with_settle_gain_check(device: DeviceModel, config: TsmdConfig, plant: str,
                           params: dict[str, Any], seeds: list[int]) -> DeviceModel:
    """The sheet with each knob's settle-gain check on its own unit, printed: calibrated under
    the sheet as a unit is by default (the paper protocol, one run per seed: its seven grid
    points are smoothed where the fast protocol's three are not, and the reading at the other
    knob's 0 moves with that; notchclutch unit 0 phi2 read a slope ratio 0.99 on the fast
    protocol and 0.91 on the paper's, docs/model.md session 25)."""
    if not seeds:
        raise DatasheetError("--settle-gain-check needs rule seeds (the sheet's unit is "
                             "calibrated once per seed)")
    t0 = time.monotonic()
    unit = config.replace(sim=dataclasses.replace(config.sim, plant=plant, params=params))
    runs = [play_protocol(unit, device, paper_protocol(), s) for s in seeds]
    checked, checks = with_settle_check(device, runs)
    for name, c in zip(("phi1", "phi2"), checks, strict=True):
        print(f"{name} settle gain on the sheet's unit, paper protocol, noise seeds "
              f"{','.join(map(str, seeds))}: {c.text()}")
    print(f"  settle-gain check: {time.monotonic() - t0:.0f} s")
    return checked


def source_header(source: Path) -> str:
    """The comment lines heading an existing sheet, without their ``# ``."""
    lines = source.read_text(encoding="utf-8").splitlines()
    head = [line for line in lines[:next((i for i, x in enumerate(lines)
                                          if not x.startswith("#")), len(lines))]]
    return "\n".join(line[2:] if line.startswith("# ") else line.lstrip("#") for line in head)
