"""`tsmd datasheet --start calibrated`: the sheet unit's sweeps measured on the state a
calibration leaves (:mod:`tsmd.datasheet_start`), in a full measurement or, with ``--update
FILE --sweep-constants``, on an existing sheet whose every other field is kept."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from tsmd.config import TsmdConfig
from tsmd.datasheet import DatasheetError, device_model, measure_device_constants, readable
from tsmd.datasheet_start import with_sweep_constants
from tsmd.profile import DeviceModel


def with_sweep_start(device: DeviceModel, config: TsmdConfig, started: Callable[[], Any],
                     seed: int) -> DeviceModel:
    """``device`` with the sweep constants it carries measured again on the plants ``started``
    gives (:func:`tsmd.datasheet_start.sheet_unit_factory`), each moved field printed."""
    ripple = {k.torque_ripple_period_deg for k in device.knobs}
    rise = {bool(k.edge_rise) for k in device.knobs}
    if len(ripple) > 1 or len(rise) > 1:
        raise DatasheetError("--sweep-constants: the sheet's knobs differ in their torque ripple "
                             "period or edge reader; a sweep reads both knobs the same way")
    t0 = time.monotonic()
    constants = measure_device_constants(started, seed, config, ripple.pop(), rise.pop())
    measured = device_model(device.device_model, constants, config, loaded_shape=True)
    updated, lines = with_sweep_constants(device, measured)
    for line in lines:
        print(f"  {line}")
    updated, dropped = readable(updated)
    for line in dropped:
        print(f"warning: {line}")
    print(f"  sweep constants: {time.monotonic() - t0:.0f} s")
    return updated


__all__ = ["with_sweep_start"]
