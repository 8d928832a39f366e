"""`tsmd datasheet --start calibrated`: the sheet unit's sweeps measured on the state a
calibration leaves (:mod:`tsmd.datasheet_start`), in a full measurement or, with ``--update
FILE --sweep-constants``, on an existing sheet whose every other field is kept."""

from __future__ import annotations

import time
from collections.abc import Callable

from simrig.plant import Plant
from tsmd.config import TsmdConfig
from tsmd.datasheet import DatasheetError, device_model, measure_device_constants, readable
from tsmd.datasheet_start import sheet_unit_factory, with_sweep_constants
from tsmd.profile import DeviceModel


def with_sweep_start(device: DeviceModel, config: TsmdConfig, factory: Callable[[], Plant],
                     start: str, seed: int) -> DeviceModel:
    """``device`` with the sweep constants it carries measured again on ``start`` (the unit
    calibrated under ``device`` first where ``calibrated``), each moved field printed."""
    ripple = {k.torque_ripple_period_deg for k in device.knobs}
    rise = {bool(k.edge_rise) for k in device.knobs}
    if len(ripple) > 1 or len(rise) > 1:
        raise DatasheetError("--sweep-constants: the sheet's knobs differ in their torque ripple "
                             "period or edge reader; a sweep reads both knobs the same way")
    t0 = time.monotonic()
    make = sheet_unit_factory(start, factory, device, seed, config)
    constants = measure_device_constants(make, seed, config, ripple.pop(), rise.pop())
    measured = device_model(device.device_model, constants, config, loaded_shape=True)
    updated, lines = with_sweep_constants(device, measured)
    for line in lines:
        print(f"  {line}")
    updated, dropped = readable(updated)
    for line in dropped:
        print(f"warning: {line}")
    print(f"  sweep constants on the {start} start: {time.monotonic() - t0:.0f} s")
    return updated


__all__ = ["with_sweep_start"]
