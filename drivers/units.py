"""Per-drive configuration and unit conversion: knob degrees <-> encoder counts, raw current <-> A.

Counts and raw current units never leave :mod:`drivers`; everything above it speaks knob degrees
and amperes. Position units on the drive are motor encoder counts (0x6064, 0x607A); current is
0x6078 in thousandths of the rated current 0x6075, so ``current_scale_A = rated_current_A / 1000``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any

from drivers.drive import DriveError


class DriveConfigError(DriveError):
    """A drive configuration key is missing, unknown or out of range."""


@dataclass(frozen=True)
class DriveConfig:
    """One knob drive: CANopen identity, scaling, limits and supervision timing."""

    node_id: int
    vendor_id: int = 0
    """Expected 0x1018:01; 0 skips the check."""
    product_code: int = 0
    """Expected 0x1018:02; 0 skips the check."""
    counts_per_motor_rev: int = 16384
    gear_ratio: float = 50.0
    """Motor revolutions per knob revolution."""
    current_scale_A: float = 0.002
    """Amperes per raw 0x6078 unit (rated current / 1000)."""
    min_deg: float = -95.0
    max_deg: float = 95.0
    max_velocity_deg_s: float = 120.0
    max_accel_deg_s2: float = 2000.0
    following_error_deg: float = 5.0
    following_error_timeout_ms: int = 20
    heartbeat_producer_ms: int = 50
    """Drive heartbeat period (0x1017)."""
    heartbeat_timeout_ms: int = 150
    """Master declares the drive lost after this long without a heartbeat."""
    master_heartbeat_timeout_ms: int = 150
    """The drive's consumer timeout for the master heartbeat (0x1016)."""
    stale_after_syncs: int = 3
    """Feedback not refreshed by this many SYNCs in a row is stale."""
    quick_stop_option: int = 6
    """0x605A: 6 = stop on the quick-stop ramp and hold in QUICK STOP ACTIVE."""
    abort_connection_option: int = 3
    """0x6007 on heartbeat loss: 1 fault, 2 disable voltage, 3 quick stop."""

    def __post_init__(self) -> None:
        _check(1 <= self.node_id <= 127, "node_id", self.node_id, "must be 1..127")
        _check(self.counts_per_motor_rev > 0, "counts_per_motor_rev", self.counts_per_motor_rev,
               "must be > 0")
        _check(self.gear_ratio > 0, "gear_ratio", self.gear_ratio, "must be > 0")
        _check(self.current_scale_A > 0, "current_scale_A", self.current_scale_A, "must be > 0")
        _check(self.min_deg < self.max_deg, "min_deg", self.min_deg, "must be < max_deg")
        _check(self.max_velocity_deg_s > 0, "max_velocity_deg_s", self.max_velocity_deg_s,
               "must be > 0")
        _check(self.max_accel_deg_s2 > 0, "max_accel_deg_s2", self.max_accel_deg_s2, "must be > 0")
        _check(self.following_error_deg > 0, "following_error_deg", self.following_error_deg,
               "must be > 0")
        _check(0 < self.heartbeat_producer_ms < self.heartbeat_timeout_ms, "heartbeat_timeout_ms",
               self.heartbeat_timeout_ms, "must exceed heartbeat_producer_ms > 0")
        _check(0 < self.master_heartbeat_timeout_ms <= 65535, "master_heartbeat_timeout_ms",
               self.master_heartbeat_timeout_ms, "must be 1..65535")
        _check(self.stale_after_syncs >= 1, "stale_after_syncs", self.stale_after_syncs,
               "must be >= 1")
        _check(self.quick_stop_option in (0, 1, 2, 5, 6), "quick_stop_option",
               self.quick_stop_option, "must be one of 0, 1, 2, 5, 6")
        _check(self.abort_connection_option in (0, 1, 2, 3), "abort_connection_option",
               self.abort_connection_option, "must be 0..3")

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> DriveConfig:
        """Build from a config mapping; ``identity: {vendor_id, product_code}`` may be nested."""
        values = dict(data)
        identity = values.pop("identity", None)
        if identity is not None:
            if not isinstance(identity, Mapping):
                raise DriveConfigError("drive key 'identity' must be a mapping")
            for key in ("vendor_id", "product_code"):
                if key in identity:
                    values[key] = identity[key]
            unknown_id = set(identity) - {"vendor_id", "product_code"}
            if unknown_id:
                raise DriveConfigError(f"unknown drive identity key(s): {sorted(unknown_id)}")
        known = {f.name: f for f in fields(cls)}
        unknown = set(values) - set(known)
        if unknown:
            raise DriveConfigError(f"unknown drive key(s): {sorted(unknown)}")
        if "node_id" not in values:
            raise DriveConfigError("drive key 'node_id' is missing")
        kwargs: dict[str, Any] = {}
        for key, value in values.items():
            integer = key == "node_id" or type(known[key].default) is int
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise DriveConfigError(f"drive key {key!r}: {value!r} is not a number")
            if integer and not isinstance(value, int):
                raise DriveConfigError(f"drive key {key!r}: {value!r} must be an integer")
            kwargs[key] = int(value) if integer else float(value)
        return cls(**kwargs)

    # -- conversions -----------------------------------------------------------------------
    @property
    def counts_per_deg(self) -> float:
        """Encoder counts per knob degree."""
        return self.counts_per_motor_rev * self.gear_ratio / 360.0

    def deg_to_counts(self, knob_deg: float) -> int:
        return round(knob_deg * self.counts_per_deg)

    def counts_to_deg(self, counts: int) -> float:
        return counts / self.counts_per_deg

    def raw_to_A(self, raw: int) -> float:
        return raw * self.current_scale_A

    def A_to_raw(self, current_A: float) -> int:
        raw = round(current_A / self.current_scale_A)
        return max(-32768, min(32767, raw))

    @property
    def rated_current_mA(self) -> int:
        """0x6075 implied by the current scale."""
        return round(self.current_scale_A * 1e6)


def _check(ok: bool, key: str, value: object, reason: str) -> None:
    if not ok:
        raise DriveConfigError(f"drive key {key!r}={value!r}: {reason}")


def interpolation_period(period_s: float) -> tuple[int, int]:
    """0x60C2 (value, index) with ``period_s = value * 10**index``, value in 1..255."""
    if not (period_s > 0 and math.isfinite(period_s)):
        raise DriveConfigError(f"loop period {period_s!r} s must be > 0")
    for index in range(-3, -7, -1):
        value = period_s * 10.0 ** (-index)
        if abs(value - round(value)) < 1e-6 and 1 <= round(value) <= 255:
            return round(value), index
    for index in range(-1, -7, -1):
        value = round(period_s * 10.0 ** (-index))
        if 1 <= value <= 255 and abs(value * 10.0**index - period_s) < 1e-6:
            return int(value), index
    raise DriveConfigError(f"loop period {period_s!r} s cannot be written to 0x60C2 exactly")
