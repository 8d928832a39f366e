"""The state a tracking scenario (`tsmd bench family`, `tsmd bench accuracy`) starts from.

In the room a probe is calibrated in the patient and its tracking follows on the same catheter:
its shaft has warmed (warmgear, twistshaft), its liner soaked (notchclutch), its tendons carry the
calibration's loads. Until session 27 every scenario ran on a freshly built plant (cold, dry)
after one unscored +-90 deg cycle, while the profile it was scored with had been read on a plant
minutes into its calibration; the start moved warmgear's figures more than most method changes
(docs/model.md, session 26 of s26-warm). The starts:

- ``calibrated`` (the default): a copy of the plant as the unit's calibration left it, then the
  one conditioning cycle, so every scenario begins from the same mechanical state on the warm,
  soaked catheter (each scenario on its own copy: the order of scenarios does not matter);
- ``conditioned``: a fresh plant and the conditioning cycle (the default until session 27);
- ``fresh``: a fresh plant, no cycle, the compensator told the tendons were never loaded.

The calibrated plant is kept beside the unit's profile (``unit-<n>.plant.pkl``) so a rerun with
``--profiles`` does not calibrate again; a profile without its plant is calibrated again
(deterministic: the same noise seed gives the same profile).
"""

from __future__ import annotations

import pickle
from collections.abc import Callable
from pathlib import Path
from typing import Any

from tsmd.carried_plant import calibrate_with_plant as calibrated_unit
from tsmd.carried_plant import carried_factory
from tsmd.profile import CatheterProfile, load_profile, save_profile

STARTS = ("calibrated", "conditioned", "fresh")
DEFAULT_START = "calibrated"
CALIBRATION_SEED = 3000
"""The noise seed of the tracking benches' calibrations (the one every earlier figure used)."""


def start_of(args: Any) -> str:
    """The start an argument namespace asks for: ``--start``, or ``fresh`` where the older
    ``--fresh`` flag is given."""
    if getattr(args, "fresh", False):
        return "fresh"
    start = getattr(args, "start", None) or DEFAULT_START
    if start not in STARTS:
        raise ValueError(f"start must be one of {STARTS}, got {start!r}")
    return str(start)


def calibrate_with_plant(device: Any, make: Callable[[], Any], seed: int = CALIBRATION_SEED
                         ) -> tuple[CatheterProfile, Any]:
    """The unit's profile from ``tsmd.calibration.calibrate`` (motor current only, the bench's
    protocol) and the plant as that calibration left it."""
    return calibrated_unit(device, make, seed)


def plant_path(profile_path: Path) -> Path:
    """Where the calibrated plant of a cached profile is kept."""
    return profile_path.with_suffix(".plant.pkl")


def cached_unit(path: Path | None, device: Any, make: Callable[[], Any], need_plant: bool,
                log: Callable[[str], None] = print) -> tuple[CatheterProfile, Any]:
    """The unit's profile (and, with ``need_plant``, its calibrated plant, else None), taken
    from ``path`` and its pickle when there, else calibrated and kept there."""
    if path is not None and path.exists() and (not need_plant or plant_path(path).exists()):
        log(f"profile {path}")
        plant = None
        if need_plant:
            with plant_path(path).open("rb") as f:
                plant = pickle.load(f)
        return load_profile(path), plant
    log("calibrating from motor current ...")
    profile, plant = calibrate_with_plant(device, make)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        if not path.exists():
            save_profile(profile, path)
        else:  # the same seed gives the same profile: the one on disk is the one scored
            profile = load_profile(path)
        with plant_path(path).open("wb") as f:
            pickle.dump(plant, f)
    return profile, plant if need_plant else None


def scenario_plant(start: str, make: Callable[[], Any], calibrated_plant: Any
                   ) -> Callable[[], Any]:
    """The plant factory one scenario run uses: a copy of the calibrated plant that goes on
    from its state (``calibrated``), else the unit built afresh."""
    if start not in STARTS:
        raise ValueError(f"start must be one of {STARTS}, got {start!r}")
    if start != "calibrated":
        return make
    if calibrated_plant is None:
        raise ValueError("a calibrated start needs the plant its calibration left")
    return carried_factory(calibrated_plant)


def conditions(start: str) -> bool:
    """Whether a scenario runs the unscored conditioning cycle first (all but ``fresh``)."""
    return start != "fresh"


def start_label(start: str) -> str:
    return {"calibrated": "calibrated plant + one conditioning cycle",
            "conditioned": "fresh plant + one conditioning cycle",
            "fresh": "fresh plant"}[start]


__all__ = ["DEFAULT_START", "STARTS", "cached_unit", "calibrate_with_plant", "conditions",
           "plant_path", "scenario_plant", "start_label", "start_of"]
