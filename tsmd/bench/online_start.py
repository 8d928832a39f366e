"""The state a `tsmd bench online` run starts from: the calibrated catheter's, or a fresh one.

In the room the probe is calibrated in the patient and used straight after: its liner has soaked
(notchclutch), its shaft warmed (twistshaft, warmgear), its tendons hold the calibration's last
loads. Until session 26 the bench calibrated one plant and ran a second, freshly built one (dry,
cold), so the online estimator learned its reference while that state still moved (docs/online.md,
session 25 round 2). ``calibrated`` (the default) runs on the plant the calibration left;
``fresh`` keeps the old start.

The calibrated plant is kept with its profile in the bench's cache (a pickle next to the profile's
YAML, keyed by the same code version), so reruns do not calibrate again.
"""

from __future__ import annotations

import pickle
import time
from pathlib import Path
from typing import Any

from simrig.scenario import ShapeChange, ShapeChangePlant
from tsmd.bench.online_units import calibrate_unit, make_unit
from tsmd.carried_plant import carried_factory
from tsmd.profile import load_profile, save_profile

STARTS = ("calibrated", "fresh")


def calibrated_with_plant(plant: str, unit: int, change: dict[str, Any] | None, device: Any,
                          cache: Path, label: str) -> tuple[Any, Any]:
    """The unit's profile (fast protocol, as :func:`tsmd.bench.online_units.calibrated`) and the
    plant as the calibration left it, both cached; a cached profile without its plant is
    calibrated again (deterministic: the same seed gives the same profile)."""
    path = cache / f"{plant}-unit{unit}-{label}.yaml"
    state = cache / f"{plant}-unit{unit}-{label}.plant.pkl"
    if path.exists() and state.exists():
        with state.open("rb") as f:
            return load_profile(path), pickle.load(f)
    t0 = time.perf_counter()
    profile, sim = calibrate_unit(plant, unit, change, device, label)
    cache.mkdir(parents=True, exist_ok=True)
    if not path.exists():
        save_profile(profile, path)
    with state.open("wb") as f:
        pickle.dump(sim.plant, f)
    print(f"  calibrated {plant} unit {unit} ({label}, plant state kept) in "
          f"{time.perf_counter() - t0:.0f} s wall", flush=True)
    return load_profile(path), sim.plant


def run_plant(start: str, plant: str, unit: int, calibrated_plant: Any,
              changes: list[ShapeChange]) -> ShapeChangePlant:
    """The plant one run drives: a copy of the calibrated one (``calibrated``; its shape as the
    calibration had it, ``changes`` on top) or the unit built afresh (``fresh``)."""
    if start == "fresh":
        return make_unit(plant, unit, changes)
    if start != "calibrated":
        raise ValueError(f"start must be one of {STARTS}, got {start!r}")
    return ShapeChangePlant(carried_factory(calibrated_plant)(), changes)


__all__ = ["STARTS", "calibrated_with_plant", "run_plant"]
