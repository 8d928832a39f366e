"""The catheters of `tsmd bench online`: a family unit with its shape changes, the product's data
sheet, and the unit's calibrated profile, cached (shared by :mod:`tsmd.bench.online` and
:mod:`tsmd.bench.online_bend`)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from simrig.family import family_member
from simrig.scenario import ShapeChange, ShapeChangePlant
from tsmd.calibration import calibrate, fast_protocol
from tsmd.config import default_sim_config
from tsmd.datasheet import device_model, measure_device_constants
from tsmd.errors import TsmdError
from tsmd.profile import load_device_model, load_profile, save_device_model, save_profile
from tsmd.replay import LockstepRunner


def shape_change(kind: str) -> dict[str, Any]:
    """``slack:MM`` (every tendon's slack grows by MM) or ``curvature:DEG`` (sheath bend)."""
    name, _, value = kind.partition(":")
    try:
        x = float(value)
    except ValueError:
        raise TsmdError(f"--change {kind!r}: expected slack:MM or curvature:DEG") from None
    if name == "slack":
        return {"slack_delta_mm": ((x, x), (x, x))}
    if name == "curvature":
        return {"sheath_curvature_deg": x}
    raise TsmdError(f"--change {kind!r}: expected slack:MM or curvature:DEG")


def make_unit(plant: str, unit: int, changes: list[Any]) -> Any:
    """Unit ``unit`` of ``plant``'s family (0 = nominal), with shape changes
    ``[ShapeChange, ...]``."""
    return ShapeChangePlant(family_member(plant, unit).build(), changes)


def device_for(plant: str, cache: Path) -> Any:
    """The data sheet of ``plant``'s family: the product's for capstan, measured on the nominal
    lumped unit (cached) for lumped."""
    base = Path(__file__).resolve().parents[2] / "profiles" / "devices" / "sim-catheter.yaml"
    if plant == "capstan":
        return load_device_model(base)
    path = cache / f"device-{plant}.yaml"
    if path.exists():
        return load_device_model(path)
    t0 = time.perf_counter()
    device = device_model(f"family-{plant}", measure_device_constants(
        family_member(plant, 0).build), default_sim_config(),
        description=load_device_model(base).description)
    cache.mkdir(parents=True, exist_ok=True)
    save_device_model(device, path)
    print(f"  data sheet of {plant} measured in {time.perf_counter() - t0:.0f} s wall",
          flush=True)
    return device


def calibrate_unit(plant: str, unit: int, change: dict[str, Any] | None, device: Any,
                   label: str) -> tuple[Any, ShapeChangePlant]:
    """One fast-protocol calibration of the unit (noise seed 3000 + unit), and the simulated
    unit as the calibration left it."""
    sim = make_unit(plant, unit, [ShapeChange(0.0, change)] if change else [])
    with LockstepRunner(None, None, "none", 3000 + unit, sim) as runner:
        profile = calibrate(runner, f"{plant}-unit{unit}-{label}", device,
                            protocol=fast_protocol())
    return profile, sim


def calibrated(plant: str, unit: int, change: dict[str, Any] | None, device: Any,
               cache: Path, label: str) -> Any:
    """The unit's profile from ``tsmd.calibration`` (fast protocol), cached."""
    path = cache / f"{plant}-unit{unit}-{label}.yaml"
    if path.exists():
        return load_profile(path)
    t0 = time.perf_counter()
    profile, _ = calibrate_unit(plant, unit, change, device, label)
    cache.mkdir(parents=True, exist_ok=True)
    save_profile(profile, path)
    print(f"  calibrated {plant} unit {unit} ({label}) in {time.perf_counter() - t0:.0f} s wall",
          flush=True)
    return profile


__all__ = ["calibrate_unit", "calibrated", "device_for", "make_unit", "shape_change"]
