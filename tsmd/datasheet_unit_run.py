"""One calibration of the data sheet's own unit on the simulated rig, its tip tracked.

Several sheet stages (release end, rounded release, level grid) read the sheet unit's tracked
sweeps against the profile the calibration makes from its current; they share this run so a
sheet unit that does not calibrate is reported the same way, naming the stage.
"""

from __future__ import annotations

from collections.abc import Callable

from simrig.plant import Plant
from tsmd.calibration.errors import CalibrationError
from tsmd.calibration.run import Calibration, run_calibration
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.errors import TsmdError
from tsmd.profile import DeviceModel
from tsmd.replay import LockstepRunner

SHEET_UNIT_SEED = 2000
"""Noise seed of the sheet unit's own runs (apart from the scored units' seeds)."""


def calibrate_sheet_unit(plant_factory: Callable[[], Plant], device: DeviceModel, stage: str,
                         seed: int = SHEET_UNIT_SEED,
                         config: TsmdConfig | None = None) -> Calibration:
    """The paper protocol's calibration of the sheet's unit under ``device`` (the sheet as
    measured so far); TsmdError naming ``stage`` if the unit does not calibrate."""
    cfg = config if config is not None else default_sim_config()
    try:
        with LockstepRunner(cfg, None, "none", seed, plant_factory()) as runner:
            return run_calibration(runner, f"datasheet-{stage.replace(' ', '-')}", device)
    except CalibrationError as exc:
        raise TsmdError(f"{stage}: the sheet's unit did not calibrate: {exc}") from None
