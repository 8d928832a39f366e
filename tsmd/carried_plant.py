"""A catheter that stays inserted between runs: the state a calibration leaves, carried on.

In the room a probe is calibrated in the patient and used straight after: its shaft has warmed
(warmgear, twistshaft), its liner soaked (notchclutch), its tendons carry the calibration's last
loads. The online and tracking benches score on that state (sessions 26-27); the data sheet's
reference unit can be characterised on it too (``tsmd datasheet --start calibrated``, session
28): after the same calibration run a clinical unit gets. Kept out of :mod:`tsmd.bench` because
a data-sheet stage may not import the benches (tests/test_import_graph.py).
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any

from tsmd.calibration import calibrate
from tsmd.config import TsmdConfig
from tsmd.profile import CatheterProfile, DeviceModel
from tsmd.replay import LockstepRunner


class CarriedPlant:
    """A plant that goes on from where an earlier run left it: the rig's reset at the start of a
    run keeps its state (the probe stays inserted), everything else is the wrapped plant's."""

    def __init__(self, plant: Any) -> None:
        self.plant = plant

    def reset(self) -> None:
        """Nothing: the catheter is not taken out between calibration and use."""

    def reshape(self, **changes: Any) -> None:
        self.plant.reshape(**changes)

    def step(self, dt_s: float, knob_deg: Any) -> Any:
        return self.plant.step(dt_s, knob_deg)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.plant, name)


def calibrate_with_plant(device: DeviceModel, make: Callable[[], Any], seed: int,
                         config: TsmdConfig | None = None) -> tuple[CatheterProfile, Any]:
    """The unit's profile from :func:`tsmd.calibration.calibrate` (motor current only, the
    product's protocol) and the plant as that calibration left it."""
    plant = make()
    with LockstepRunner(config, None, "none", seed, plant) as runner:
        profile = calibrate(runner, "sim-bench", device)
    return profile, plant


def carried_factory(calibrated_plant: Any) -> Callable[[], CarriedPlant]:
    """A plant factory whose every plant is its own copy of ``calibrated_plant``, going on from
    its state (each run the same start, in any order; the calibrated plant stays put)."""

    def carried() -> CarriedPlant:
        return CarriedPlant(copy.deepcopy(calibrated_plant))

    return carried


__all__ = ["CarriedPlant", "calibrate_with_plant", "carried_factory"]
