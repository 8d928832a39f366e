"""Boot of the CANopen master: NMT reset, identity checks, PDO mapping and parameters by SDO,
NMT start and supervision (docs/drivers.md, "Boot")."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from drivers import od as o
from drivers.drive import DriveError, FaultKind
from drivers.drive_image import DriveImage
from drivers.master_exchange import MasterExchange

MOTOR_SPEED_HEADROOM = 1.25
"""0x6080 = knob velocity limit x gear x this: room for the position loop's transients."""


class MasterBoot(MasterExchange):
    """Boot and (re-)configuration of the drives of :class:`CanOpenDrives`."""

    def boot(self) -> None:
        self.pump()  # frames from before the reset (an earlier boot-up) must not count
        for d in self._drives:
            d.supervised = False
            d.has_feedback = False
            d.nmt_state = None
            d.rebooted = False
            d.homed = False
            self._send(0x000, bytes((0x81, d.node_id)))
        self._wait_until(lambda d: d.nmt_state is not None, self.timeouts.boot_s,
                         "boot-up message after NMT reset node")
        for d in self._drives:
            try:
                self._configure(d)
            except DriveError as exc:
                reason = str(exc).removeprefix(f"{d.name}: ")
                if reason.startswith("boot failed"):
                    raise
                self._boot_failed(d, reason)
        self._start_supervised(self._drives)

    def _start_supervised(self, drives: Sequence[DriveImage]) -> None:
        """NMT start, wait for OPERATIONAL heartbeats, then supervise (heartbeat, TPDO age)."""
        for d in drives:
            d.nmt_state = None
            self._send(0x000, bytes((0x01, d.node_id)))
        self._wait_until(lambda d: d.nmt_state == 0x05, self.timeouts.boot_s,
                         "heartbeat in OPERATIONAL after NMT start", drives)
        now = self.clock.now_s()
        for d in drives:
            d.supervised = True
            d.heartbeat_lost = False
            d.last_heartbeat_s = now
            d.controlword = 0
            d.age_syncs = 0
            d.stale_reported = False
            d.rebooted = False

    def _configure(self, d: DriveImage) -> None:
        c = d.config
        i = d.index
        device_type = int(self.sdo_read(i, o.DEVICE_TYPE))
        if device_type & 0xFFFF != o.DEVICE_PROFILE_402:
            self._boot_failed(d, f"device type 0x{device_type:08X} is not a CiA 402 drive")
        vendor = int(self.sdo_read(i, o.IDENTITY, 1))
        product = int(self.sdo_read(i, o.IDENTITY, 2))
        if (c.vendor_id and vendor != c.vendor_id) or (c.product_code and
                                                        product != c.product_code):
            self._boot_failed(d, f"identity 0x1018 is vendor 0x{vendor:08X} product "
                                 f"0x{product:08X}, config expects vendor 0x{c.vendor_id:08X} "
                                 f"product 0x{c.product_code:08X}")
        rated_mA = int(self.sdo_read(i, o.MOTOR_RATED_CURRENT))
        if abs(rated_mA - c.rated_current_mA) > 0.01 * c.rated_current_mA:
            self._boot_failed(d, f"motor rated current 0x6075 is {rated_mA} mA but "
                                 f"current_scale_A={c.current_scale_A} implies "
                                 f"{c.rated_current_mA} mA")
        n = d.node_id
        value, exponent = self.interpolation
        cpd = d.cpd
        writes: list[tuple[int, int, int]] = [
            (o.RPDO1_COMM, 1, 0x80000000 | (0x200 + n)),
            (o.RPDO1_COMM, 2, 1),
            (o.RPDO1_MAP, 0, 0),
            *[(o.RPDO1_MAP, k + 1, o.mapping_entry(*m)) for k, m in enumerate(o.RPDO1_MAPPING)],
            (o.RPDO1_MAP, 0, len(o.RPDO1_MAPPING)),
            (o.RPDO1_COMM, 1, 0x200 + n),
            (o.RPDO2_COMM, 1, 0x80000000 | (0x300 + n)),
            (o.TPDO1_COMM, 1, 0x80000000 | (0x180 + n)),
            (o.TPDO1_COMM, 2, 1),
            (o.TPDO1_MAP, 0, 0),
            *[(o.TPDO1_MAP, k + 1, o.mapping_entry(*m)) for k, m in enumerate(o.TPDO1_MAPPING)],
            (o.TPDO1_MAP, 0, len(o.TPDO1_MAPPING)),
            (o.TPDO1_COMM, 1, 0x180 + n),
            (o.TPDO2_COMM, 1, 0x80000000 | (0x280 + n)),
            (o.CYCLE_PERIOD, 0, round(self.period_s * 1e6)),
            (o.INTERPOLATION_PERIOD, 1, value),
            (o.INTERPOLATION_PERIOD, 2, exponent),
            (o.MODES_OF_OPERATION, 0, o.CSP_MODE),
            (o.SOFTWARE_POSITION_LIMIT, 1, d.min_counts),
            (o.SOFTWARE_POSITION_LIMIT, 2, d.max_counts),
            (o.MAX_PROFILE_VELOCITY, 0, round(c.max_velocity_deg_s * cpd)),
            (o.MAX_MOTOR_SPEED, 0, round(c.max_velocity_deg_s * c.gear_ratio / 6.0
                                         * MOTOR_SPEED_HEADROOM)),
            (o.QUICK_STOP_DECELERATION, 0, round(c.max_accel_deg_s2 * cpd)),
            (o.FOLLOWING_ERROR_WINDOW, 0, round(c.following_error_deg * cpd)),
            (o.FOLLOWING_ERROR_TIMEOUT, 0, c.following_error_timeout_ms),
            (o.QUICK_STOP_OPTION, 0, c.quick_stop_option),
            (o.ABORT_CONNECTION_OPTION, 0, c.abort_connection_option),
            (o.PRODUCER_HEARTBEAT, 0, c.heartbeat_producer_ms),
            (o.CONSUMER_HEARTBEAT, 1, (self.master_node_id << 16) | c.master_heartbeat_timeout_ms),
        ]
        for index, subindex, val in writes:
            self.sdo_write(i, index, subindex, val)

    def _boot_failed(self, d: DriveImage, reason: str) -> None:
        self._event(FaultKind.BOOT_FAILED, d.index, f"{d.name}: {reason}")
        raise DriveError(f"{d.name}: boot failed: {reason}")

    def _wait_until(self, done: Callable[[DriveImage], bool], timeout_s: float, what: str,
                    drives: Sequence[DriveImage] | None = None) -> None:
        drives = self._drives if drives is None else drives
        deadline = self.clock.now_s() + timeout_s
        while not all(done(d) for d in drives):
            if self.clock.now_s() > deadline:
                missing = [d for d in drives if not done(d)]
                for d in missing:
                    self._event(FaultKind.BOOT_FAILED, d.index,
                                f"{d.name}: no {what} within {timeout_s} s")
                raise DriveError(f"{missing[0].name}: boot failed: no {what} within "
                                 f"{timeout_s} s")
            self._wait()
