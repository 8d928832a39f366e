"""The daemon's configuration: a YAML file read into frozen dataclasses, strictly.

Every key is known, typed and range-checked; a bad file is refused with a
:class:`ConfigError` naming the key path (``loop.rate_hz``, ``drives[1].node_id``) and the
reason, before anything touches a drive. Every key is documented in docs/configuration.md.
"""

from __future__ import annotations

import dataclasses
import typing
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, Literal

import yaml

from drivers.drive import DriveError
from drivers.units import DriveConfig, MasterTimeouts
from tsmd.compensation.safety import DEFAULT_MAX_ACCEL_DEG_S2, DEFAULT_MAX_VELOCITY_DEG_S
from tsmd.errors import TsmdError
from tsmd.strict_dataclass import SchemaError, build_dataclass
from tsmd.yamlfile import read_yaml

DEFAULT_CONFIG_PATH = Path("/etc/tsmd/tsmd.yaml")

CompensationMethod = Literal["none", "paper", "ours"]
CanLogFormat = Literal["none", "blf", "asc"]


class ConfigError(TsmdError, ValueError):
    """The configuration is not valid; the message names the key path and the reason."""


def _range(lo: float | None = None, hi: float | None = None) -> dict[str, Any]:
    return {"range": (lo, hi)}


@dataclass(frozen=True)
class RealtimeConfig:
    """Real-time scheduling of the loop thread; each item degrades to a warning if refused."""

    priority: int = field(default=80, metadata=_range(0, 99))
    """SCHED_FIFO priority of the loop thread; 0 keeps the normal scheduler."""
    cpu: int | None = field(default=None, metadata=_range(0, 1023))
    """CPU the loop thread is pinned to; null: no affinity change."""
    lock_memory: bool = True
    """mlockall(MCL_CURRENT | MCL_FUTURE) so the hot path never page-faults."""


@dataclass(frozen=True)
class LoopConfig:
    rate_hz: float = field(default=250.0, metadata=_range(10.0, 1000.0))
    realtime: RealtimeConfig = field(default_factory=RealtimeConfig)
    overrun_fault_streak: int = field(default=5, metadata=_range(1, 10_000))
    """This many overruns in a row put the loop into FAULT."""
    stale_feedback_syncs: int = field(default=3, metadata=_range(1, 1000))
    """Feedback older than this many SYNCs while enabled is a fault."""

    @property
    def period_s(self) -> float:
        return 1.0 / self.rate_hz


@dataclass(frozen=True)
class TimeoutsConfig:
    """How long the CANopen master waits (drivers.units.MasterTimeouts); each failure names the
    drive, the step and the statusword seen."""

    sdo_s: float = field(default=0.5, metadata=_range(0.01, 60.0))
    boot_s: float = field(default=2.0, metadata=_range(0.05, 600.0))
    enable_s: float = field(default=0.5, metadata=_range(0.01, 60.0))
    disable_s: float = field(default=0.5, metadata=_range(0.01, 60.0))
    quick_stop_s: float = field(default=0.5, metadata=_range(0.01, 60.0))
    fault_reset_s: float = field(default=0.5, metadata=_range(0.01, 60.0))

    def master(self) -> MasterTimeouts:
        return MasterTimeouts(**dataclasses.asdict(self))


@dataclass(frozen=True)
class BusConfig:
    interface: str = "socketcan"
    """python-can interface name (socketcan in production, virtual in tests)."""
    channel: str = "can0"
    bitrate: int = field(default=1_000_000, metadata=_range(10_000, 1_000_000))
    log_format: CanLogFormat = "none"
    """Log the CAN traffic with python-can's own writer (BLF or ASC) into recording.dir."""
    timeouts: TimeoutsConfig = field(default_factory=TimeoutsConfig)


@dataclass(frozen=True)
class KnobLimitsConfig:
    min_deg: float = field(default=-90.0, metadata=_range(-360.0, 360.0))
    max_deg: float = field(default=90.0, metadata=_range(-360.0, 360.0))
    max_velocity_deg_s: float = field(default=DEFAULT_MAX_VELOCITY_DEG_S,
                                      metadata=_range(1e-3, 10_000.0))
    max_accel_deg_s2: float = field(default=DEFAULT_MAX_ACCEL_DEG_S2, metadata=_range(1e-3, 1e6))


@dataclass(frozen=True)
class ApiConfig:
    socket_path: str = "/run/tsmd/tsmd.sock"
    socket_mode: int = field(default=0o660, metadata=_range(0, 0o777))
    max_line_bytes: int = field(default=4096, metadata=_range(64, 1 << 20))
    max_clients: int = field(default=16, metadata=_range(1, 1024))
    max_subscribe_hz: float = field(default=250.0, metadata=_range(0.1, 1000.0))
    idle_timeout_s: float = field(default=30.0, metadata=_range(0.1, 86_400.0))
    """A client that sends no request (and streams nothing) for this long is closed."""
    partial_line_timeout_s: float = field(default=5.0, metadata=_range(0.05, 3600.0))
    """A request line must end within this long of its first byte."""
    accepts_per_s: float = field(default=200.0, metadata=_range(1.0, 100_000.0))
    """New connections accepted per second at most (a connect storm must not take ticks)."""


@dataclass(frozen=True)
class ProfilesConfig:
    dir: str = "/var/lib/tsmd/profiles"
    active: str | None = None
    """Catheter id loaded at start; null: no profile (compensation 'none' until one is loaded)."""
    device_model: str | None = None
    """Device model YAML (data-sheet constants) used by calibration; null: the packaged one."""


@dataclass(frozen=True)
class CompensationConfig:
    method: CompensationMethod = "ours"
    enabled: bool = True
    fresh_catheter: bool = False
    """The catheter starts never loaded (straight, as made): ours' first release follows the
    profile's fresh hold. False: it has been loaded before (calibrated), the usual case."""


@dataclass(frozen=True)
class OnlineConfig:
    """Online re-estimation of the dead-zone edges from motor current (docs/online.md).

    The numbers are :class:`tsmd.online.EstimatorOptions`' and the worker's; off by default
    until validated on a real probe.
    """

    enabled: bool = False
    rate_deg_s: float = field(default=4.0, metadata=_range(0.1, 100.0))
    """How fast an applied offset moves towards a new estimate."""
    max_offset_deg: float = field(default=12.0, metadata=_range(0.5, 45.0))
    """A larger change is not followed: a warning, the offset stays."""
    deadband_deg: float = field(default=0.4, metadata=_range(0.0, 5.0))
    """Changes smaller than this are not applied (hysteresis against noise)."""
    gate_deg: float = field(default=1.5, metadata=_range(0.1, 20.0))
    """A measurement this far from the estimate is a suspect until confirmed."""


@dataclass(frozen=True)
class RecordingConfig:
    enabled: bool = False
    dir: str = "/var/lib/tsmd/recordings"
    flush_interval_s: float = field(default=1.0, metadata=_range(0.01, 3600.0))


@dataclass(frozen=True)
class SimConfig:
    plant: str = "simrig.plants.capstan:make_tendon_sheath_plant"
    """``module:factory`` of the simulated catheter (simrig.plant.load_plant)."""
    params: dict[str, Any] = field(default_factory=dict)
    seed: int = field(default=0, metadata=_range(0, 2**32 - 1))
    tracker_noise_deg: float = field(default=0.2, metadata=_range(0.0, 10.0))


@dataclass(frozen=True)
class LimitsConfig:
    phi1: KnobLimitsConfig = field(default_factory=KnobLimitsConfig)
    phi2: KnobLimitsConfig = field(default_factory=KnobLimitsConfig)

    def knobs(self) -> tuple[KnobLimitsConfig, KnobLimitsConfig]:
        return (self.phi1, self.phi2)


@dataclass(frozen=True)
class TsmdConfig:
    loop: LoopConfig = field(default_factory=LoopConfig)
    bus: BusConfig = field(default_factory=BusConfig)
    drives: list[dict[str, Any]] = field(default_factory=list)
    """One mapping per knob drive, validated against drivers.units.DriveConfig."""
    limits: LimitsConfig = field(default_factory=LimitsConfig)
    api: ApiConfig = field(default_factory=ApiConfig)
    profiles: ProfilesConfig = field(default_factory=ProfilesConfig)
    compensation: CompensationConfig = field(default_factory=CompensationConfig)
    online: OnlineConfig = field(default_factory=OnlineConfig)
    recording: RecordingConfig = field(default_factory=RecordingConfig)
    sim: SimConfig = field(default_factory=SimConfig)

    def replace(self, **changes: Any) -> TsmdConfig:
        return dataclasses.replace(self, **changes)


def _validate(config: TsmdConfig) -> None:
    for name, knob in (("phi1", config.limits.phi1), ("phi2", config.limits.phi2)):
        if knob.min_deg >= knob.max_deg:
            raise ConfigError(
                f"limits.{name}: min_deg ({knob.min_deg}) must be below max_deg ({knob.max_deg})")
    if config.drives and len(config.drives) != 2:
        raise ConfigError(f"drives: expected 2 drives (phi1, phi2), got {len(config.drives)}")
    drives = _parse_drives(config)
    for i, (drive, name) in enumerate(zip(drives, ("phi1", "phi2"), strict=False)):
        knob = getattr(config.limits, name)
        if knob.min_deg < drive.min_deg or knob.max_deg > drive.max_deg:
            raise ConfigError(
                f"limits.{name}: [{knob.min_deg}, {knob.max_deg}] deg exceeds the range of "
                f"drives[{i}] [{drive.min_deg}, {drive.max_deg}]")
        if knob.max_velocity_deg_s > drive.max_velocity_deg_s:
            raise ConfigError(
                f"limits.{name}.max_velocity_deg_s: {knob.max_velocity_deg_s} exceeds "
                f"drives[{i}].max_velocity_deg_s {drive.max_velocity_deg_s}")
    if not config.api.socket_path:
        raise ConfigError("api.socket_path: must not be empty")


def parse_config(data: Any, source: str = "<config>") -> TsmdConfig:
    """Validate an already-parsed YAML document."""
    try:
        config = build_dataclass(TsmdConfig, data, "")
        _validate(config)
    except (ConfigError, SchemaError) as exc:
        raise ConfigError(f"{source}: {exc}") from None
    return typing.cast(TsmdConfig, config)


def load_config(path: str | Path = DEFAULT_CONFIG_PATH) -> TsmdConfig:
    """Read and validate a YAML configuration file."""
    p = Path(path)
    if p == DEFAULT_CONFIG_PATH and not p.exists():  # a new user's first `tsmd run`
        raise ConfigError(f"{p}: no such file (the default configuration): pass --config FILE, "
                          "or --sim for the simulated rig")
    data = read_yaml(p, ConfigError)
    try:
        return parse_config(data, source=str(p))
    except RecursionError:
        raise ConfigError(f"{p}: nested too deeply to be a configuration") from None


def default_sim_config() -> TsmdConfig:
    """The packaged configuration of the in-process simulated rig (tsmd/data/sim.yaml)."""
    text = resources.files("tsmd").joinpath("data/sim.yaml").read_text(encoding="utf-8")
    return parse_config(yaml.safe_load(text), source="tsmd/data/sim.yaml")


def drive_configs(config: TsmdConfig) -> list[DriveConfig]:
    """The two knob drives as ``drivers.units.DriveConfig`` objects (a configuration may leave
    ``drives`` out, but nothing that runs drives can do without them)."""
    out = _parse_drives(config)
    if len(out) != 2:
        raise ConfigError(f"drives: expected 2 drives (phi1, phi2), got {len(out)}: the "
                          "configuration must list the knob drives (see docs/configuration.md)")
    return out


def _parse_drives(config: TsmdConfig) -> list[DriveConfig]:
    out = []
    for i, entry in enumerate(config.drives):
        try:
            out.append(DriveConfig.from_dict(entry))
        except (DriveError, TypeError, ValueError) as exc:
            raise ConfigError(f"drives[{i}]: {exc}") from None
    return out


PACKAGE_ROOT = Path(__file__).resolve().parent.parent
"""The source tree (profiles/, devices/ ship next to the package)."""


def resolve_data_path(path: str) -> Path:
    """Relative paths: the working directory first, then the source tree (profiles/...)."""
    p = Path(path)
    if p.is_absolute() or p.exists():
        return p
    candidate = PACKAGE_ROOT / p
    return candidate if candidate.exists() else p
