"""Per-drive configuration and unit conversion: knob degrees <-> encoder counts, raw current <-> A.

Counts and raw current units never leave :mod:`drivers`; everything above it speaks knob degrees
and amperes. Position units on the drive are motor encoder counts (0x6064, 0x607A); current is
0x6078 in thousandths of the rated current 0x6075, so ``current_scale_A = rated_current_A / 1000``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

from drivers.drive import DriveError


class DriveConfigError(DriveError):
    """A drive configuration key is missing, unknown or out of range."""


HOMING_METHODS: dict[str, int] = {
    "none": 0,
    "current_position": 37,
    "index_negative": 33,
    "index_positive": 34,
    "hard_stop_positive": -3,
    "hard_stop_negative": -4,
}
"""0x6098 homing methods we run, by name. 35 is accepted as the older number of 37.

33/34 and 35/37 are CiA 402 methods; -3/-4 (search a hard stop, detected by the motor current
exceeding 0x2080) are manufacturer-specific, numbered as several servo drives number them.
"""
_HOMING_NUMBERS = {**{v: k for k, v in HOMING_METHODS.items()}, 35: "current_position"}


@dataclass(frozen=True)
class HomingConfig:
    """How one drive finds the knob's zero reference (CiA 402 Homing Mode, 0x6060 = 6).

    ``method: none`` (an absolute encoder, or a robot whose zero needs no reference) skips
    homing. After homing the position reads ``-home_offset_deg`` at the home position (0x607C
    is the knob zero minus the home position): a hard stop 100 deg below straight is
    ``home_offset_deg: 100``; a catheter mounted straight uses ``current_position`` with 0.
    """

    method: int = 0
    """0x6098, see :data:`HOMING_METHODS` (names or numbers in a config)."""
    required: bool = False
    """Set points are refused until this drive is homed (the daemon enforces it)."""
    at_start: bool = False
    """Home when the daemon starts (else only on request): a search moves the knob."""
    home_offset_deg: float = 0.0
    switch_speed_deg_s: float = 10.0
    """0x6099:01, speed while searching the hard stop or index."""
    zero_speed_deg_s: float = 2.0
    """0x6099:02, speed while backing off to the zero."""
    accel_deg_s2: float = 100.0
    """0x609A."""
    current_threshold_A: float = 0.3
    """0x2080: motor current above which a hard stop is reached (methods -3/-4)."""
    timeout_s: float = 30.0
    """The master gives up (and quick-stops) when homing takes longer."""

    def __post_init__(self) -> None:
        _check(self.method in _HOMING_NUMBERS, "homing.method", self.method,
               f"must be one of {', '.join(HOMING_METHODS)} (or 0x6098 numbers "
               f"{sorted(_HOMING_NUMBERS)})")
        _check(not (self.required and self.method == 0), "homing.required", self.required,
               "needs a homing method other than none")
        _check(not (self.at_start and self.method == 0), "homing.at_start", self.at_start,
               "needs a homing method other than none")
        _check(math.isfinite(self.home_offset_deg), "homing.home_offset_deg",
               self.home_offset_deg, "must be finite")
        for key in ("switch_speed_deg_s", "zero_speed_deg_s", "accel_deg_s2",
                    "current_threshold_A", "timeout_s"):
            value = getattr(self, key)
            _check(math.isfinite(value) and value > 0, f"homing.{key}", value, "must be > 0")

    @property
    def enabled(self) -> bool:
        return self.method != 0

    @property
    def method_name(self) -> str:
        return _HOMING_NUMBERS[self.method]

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> HomingConfig:
        """From a config mapping; ``method`` may be a name (``current_position``) or number."""
        if not isinstance(data, Mapping):
            raise DriveConfigError("drive key 'homing' must be a mapping")
        known = {f.name: f for f in fields(cls)}
        unknown = set(data) - set(known)
        if unknown:
            raise DriveConfigError(f"unknown homing key(s): {sorted(unknown)}")
        kwargs: dict[str, Any] = {}
        for key, value in data.items():
            if key == "method":
                if isinstance(value, str) and value in HOMING_METHODS:
                    value = HOMING_METHODS[value]
                elif isinstance(value, bool) or not isinstance(value, int):
                    raise DriveConfigError(f"drive key 'homing.method': {value!r} is not one "
                                           f"of {', '.join(HOMING_METHODS)}")
            elif key in ("required", "at_start"):
                if not isinstance(value, bool):
                    raise DriveConfigError(f"drive key 'homing.{key}': {value!r} must be "
                                           "true or false")
            elif isinstance(value, bool) or not isinstance(value, int | float):
                raise DriveConfigError(f"drive key 'homing.{key}': {value!r} is not a number")
            else:
                value = float(value)
            kwargs[key] = value
        return cls(**kwargs)


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
    homing: HomingConfig = field(default_factory=HomingConfig)
    """Zero reference of the knob; method ``none`` (the default) skips homing."""

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
        homing = values.pop("homing", None)
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
        if homing is not None:
            kwargs["homing"] = HomingConfig.from_dict(homing)
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


@dataclass(frozen=True)
class MasterTimeouts:
    """How long the master waits for each kind of answer before it names the culprit."""

    sdo_s: float = 0.5
    """One SDO request/response."""
    boot_s: float = 2.0
    """Boot-up message after NMT reset, OPERATIONAL heartbeat after NMT start."""
    enable_s: float = 0.5
    disable_s: float = 0.5
    quick_stop_s: float = 0.5
    fault_reset_s: float = 0.5

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            _check(isinstance(value, int | float) and math.isfinite(value) and value > 0,
                   f"timeouts.{f.name}", value, "must be a number > 0")

    def transition_s(self, transition: str) -> float:
        """Timeout of a state-machine transition: enable, disable, quick stop, fault reset."""
        return {"enable": self.enable_s, "disable": self.disable_s,
                "quick stop": self.quick_stop_s,
                "fault reset": self.fault_reset_s}.get(transition, self.enable_s)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> MasterTimeouts:
        if not isinstance(data, Mapping):
            raise DriveConfigError("timeouts must be a mapping")
        unknown = set(data) - {f.name for f in fields(cls)}
        if unknown:
            raise DriveConfigError(f"unknown timeout key(s): {sorted(unknown)}")
        for key, value in data.items():
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise DriveConfigError(f"timeouts.{key}: {value!r} is not a number")
        return cls(**{k: float(v) for k, v in data.items()})


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
