"""`tsmd datasheet`'s measurements beyond the sweeps in a full measurement: the coupling of the
tip planes, the tip's backlash growth, the release end, the loaded shape over the other knob,
the bend relation; each one the sheet with its fields added and a line printed."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable

from simrig.plant import Plant
from tsmd.config import TsmdConfig
from tsmd.datasheet_amplitude import measure_tip_backlash_gains
from tsmd.datasheet_bend import rig_calibration, sheet_with_bend
from tsmd.datasheet_bend_slope import rig_slope_reader
from tsmd.datasheet_coupling import measure_other_tip_gains
from tsmd.datasheet_release_end import measure_release_end_offsets
from tsmd.datasheet_shape_grid import measure_shape_grids
from tsmd.profile import DeviceModel


def with_coupling(device: DeviceModel, config: TsmdConfig, factory: Callable[[], Plant],
                   seed: int) -> DeviceModel:
    """The sheet with each knob's coupling to the other plane (its unit swept with the other
    knob held at -90 and +90 deg)."""
    t0 = time.monotonic()
    edges = tuple(min(abs(edge(k.reference_dead_zone_pos_deg)),
                      abs(edge(k.reference_dead_zone_neg_deg))) for k in device.knobs)
    gains = measure_other_tip_gains(factory, (edges[0], edges[1]), seed, config)
    knobs = tuple(dataclasses.replace(k, other_tip_gain=round(g, 4))
                  for k, g in zip(device.knobs, gains, strict=True))
    print(f"  other-plane coupling: phi1 {gains[0]:+.4f}, phi2 {gains[1]:+.4f} tip deg per "
          f"other tip deg ({time.monotonic() - t0:.0f} s)")
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def with_tip_backlash_gain(device: DeviceModel, config: TsmdConfig,
                            factory: Callable[[], Plant], seed: int, by: str = "threshold"
                            ) -> DeviceModel:
    """The sheet with each knob's tip backlash growth per degree of reversal amplitude, the
    backlash read ``by`` the 1 deg threshold or the lines' corners (its own key)."""
    t0 = time.monotonic()
    gains = measure_tip_backlash_gains(factory, seed, config, by)
    rounded = [None if g is None else round(g, 3) for g in gains]
    knobs = tuple(dataclasses.replace(k, reference_tip_backlash_gain=g) if by == "threshold"
                  else dataclasses.replace(k, reference_tip_line_backlash_gain=g)
                  for k, g in zip(device.knobs, rounded, strict=True))
    print(f"  tip backlash gain by {by} (60 -> 90 deg reversals): phi1 {or_none(gains[0], 3)}, "
          f"phi2 {or_none(gains[1], 3)} ({time.monotonic() - t0:.0f} s)")
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def with_release_end_offset(device: DeviceModel, config: TsmdConfig,
                             factory: Callable[[], Plant], seed: int) -> DeviceModel:
    """The sheet with each knob's offset of the tip's release end from the current's and the
    tip's plateau there (both or neither)."""
    t0 = time.monotonic()
    read = measure_release_end_offsets(factory, device, seed, config)
    knobs = tuple(k if r is None else dataclasses.replace(
        k, reference_release_end_offset_deg=round(r[0], 2),
        reference_release_plateau_deg=round(r[1], 2)) for k, r in zip(device.knobs, read,
                                                                       strict=True))
    print("  release end, tip minus current / tip plateau: " + ", ".join(
        f"{n} {'none' if r is None else f'{r[0]:+.2f} / {r[1]:.2f}'} deg"
        for n, r in zip(("phi1", "phi2"), read, strict=True))
          + f" ({time.monotonic() - t0:.0f} s)")
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def with_shape_grid(device: DeviceModel, config: TsmdConfig, factory: Callable[[], Plant],
                     seed: int) -> DeviceModel:
    """The sheet with each knob's loaded-branch templates over the other knob's angle."""
    t0 = time.monotonic()
    grids = measure_shape_grids(factory, [round(k.omega, 2) for k in device.knobs], seed, config)
    knobs = tuple(dataclasses.replace(k, loaded_shape_grid=g)
                  for k, g in zip(device.knobs, grids, strict=True))
    for name, (pos, _neg) in zip(("phi1", "phi2"), grids, strict=True):
        # the template's mean slope over its first 30 deg past the edge, per other-knob angle
        print(f"  {name} loaded shape over the other knob: " + " ".join(
            f"{a:+.0f}:{s.at(30.0) / 30.0:.2f}"
            for a, s in zip(pos.other_knob_deg, pos.shapes, strict=True)))
    print(f"  loaded-shape grid: {time.monotonic() - t0:.0f} s")
    return dataclasses.replace(device, knobs=(knobs[0], knobs[1]))


def edge(value: float | None) -> float:
    """A sheet's reference edge, or where the family's plants have theirs when it lacks one."""
    return 20.0 if value is None else float(value)


def with_bend(device: DeviceModel, config: TsmdConfig,
               factory: Callable[[], Plant], slopes: bool) -> DeviceModel:
    """The sheet with the product's bend relation, from its unit calibrated straight and bent
    (without one, said in one line, when no bend moved an edge)."""
    t0 = time.monotonic()
    device, line = sheet_with_bend(device, rig_calibration(factory, device, config),
                                   read_slopes=(rig_slope_reader(factory, device)
                                                if slopes else None))
    print(f"{line}; {time.monotonic() - t0:.0f} s")
    return device


def or_none(value: float | None, decimals: int) -> str:
    """A figure for a printed line: ``none`` where it was not measured."""
    return "none" if value is None else f"{value:.{decimals}f}"
