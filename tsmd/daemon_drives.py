"""The drives a daemon runs: the master on the configured CAN bus (with its frame log) and
homing at start. Separate from :mod:`tsmd.daemon` so that the daemon only orders the parts."""

from __future__ import annotations

import time
from typing import Any

import can

from drivers.canlog import TappedBus
from drivers.canopen_master import CanOpenDrives
from drivers.drive import DriveError, KnobDrives
from drivers.units import DriveConfig
from tsmd.config import TsmdConfig, resolve_data_path
from tsmd.errors import DaemonError


def open_bus_drives(config: TsmdConfig, drive_cfgs: list[DriveConfig], log: Any
                    ) -> KnobDrives:
    """The master on the configured bus; the loop thread polls it every tick.

    Polling (no python-can notifier thread) leaves one thread touching the bus and one
    fewer thread competing with the loop for the GIL.
    """
    bus_cfg = config.bus
    kwargs: dict[str, Any] = {}
    if bus_cfg.interface == "udp_multicast":  # it echoes our own frames: accept only theirs
        kwargs["can_filters"] = [{"can_id": base + c.node_id, "can_mask": 0x7FF}
                                 for c in drive_cfgs for base in (0x080, 0x180, 0x580, 0x700)]
    try:
        bus: can.BusABC = can.Bus(interface=bus_cfg.interface, channel=bus_cfg.channel,
                                  bitrate=bus_cfg.bitrate, **kwargs)
    except (can.CanError, OSError, ValueError, ImportError) as exc:
        raise DaemonError(f"cannot open CAN interface {bus_cfg.interface!r} channel "
                          f"{bus_cfg.channel!r}: {exc}", "drive") from None
    bus = can_log(config, bus, log)
    return CanOpenDrives(bus, drive_cfgs, config.loop.period_s, receive="poll",
                         own_bus=True, timeouts=config.bus.timeouts.master())


def can_log(config: TsmdConfig, bus: can.BusABC, log: Any) -> can.BusABC:
    """bus.log_format: every frame sent and received, in python-can's BLF or ASC writer."""
    fmt = config.bus.log_format
    if fmt == "none":
        return bus
    directory = resolve_data_path(config.recording.dir)
    directory.mkdir(parents=True, exist_ok=True)
    stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
    path = directory / f"tsmd-can-{stamp}.{fmt}"
    log.info("logging CAN traffic", path=str(path), format=fmt)
    # the bus owns the writer: closing the drives stops it after the last frame
    return TappedBus(bus, [can.Logger(str(path))])


def home_at_start(drives: KnobDrives, drive_cfgs: list[DriveConfig], home_all: bool,
                  log: Any) -> None:
    """Home the drives whose config says ``at_start`` (or all, with ``home_all``: ``tsmd run
    --home``). Before the loop thread exists, so homing owns the bus alone; a failure fails
    the start."""
    chosen = [i for i, c in enumerate(drive_cfgs)
              if c.homing.method != 0 and (c.homing.at_start or home_all)]
    if not chosen:
        return
    log.info("homing", drives=chosen, methods=[drive_cfgs[i].homing.method_name for i in chosen])
    try:
        status = drives.home(chosen)
    except DriveError as exc:
        raise DaemonError(f"homing failed: {exc}", "homing") from None
    log.info("homed", drives=chosen, offsets_deg=[status[i].home_offset_deg for i in chosen])
