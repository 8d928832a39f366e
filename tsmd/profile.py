"""Per-catheter profiles and device models (YAML, versioned schema).

A *device model* holds the data-sheet constants of a catheter type (slope omega, the reference
points of design assumption 1, knob limits). A *profile* holds what calibration identified for one
catheter: per knob the dead zone and backlash grids over the other knob's angle, H, the
interpolation method, the tension play's parameters (method ``ours``) and the quality figures.
A knob's ``ours`` block written by tsmd before the tension play is read past with a warning:
its constants came from a data sheet measured on the scored unit; method ``ours`` then asks
for a recalibration.

Loading validates everything and raises :class:`ProfileError` naming the file, the key and the
reason. Saving is atomic and keeps the previous profile as ``<file>.bak``.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import math
import os
import re
import shutil
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from tsmd.compensation.grid import CALIBRATION_GRID_DEG, INTERPOLATION_METHODS
from tsmd.compensation.paper import at_other_knob_zero, plateau_heights
from tsmd.compensation.safety import KnobLimits
from tsmd.compensation.tension_play import (
    TensionPlayParams,
    tension_play_from_mapping,
    tension_play_to_mapping,
)
from tsmd.errors import TsmdError
from tsmd.yamlfile import read_yaml

PROFILE_SCHEMA_VERSION = 1
DEVICE_SCHEMA_VERSION = 1
KNOB_NAMES: tuple[str, str] = ("phi1", "phi2")
ANGLE_RANGE_DEG = 360.0
"""Every angle in a profile (knob or tip) must lie within +-ANGLE_RANGE_DEG: a larger value is
almost certainly in the wrong unit (radians are caught by the omega and range checks instead)."""
OMEGA_RANGE: tuple[float, float] = (0.2, 5.0)
"""Plausible tip-per-knob slopes; outside this the value is a unit or sign mistake."""
_ID_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,63}$")
_log = logging.getLogger(__name__)


class ProfileError(TsmdError, ValueError):
    """A profile or device model is missing, malformed or implausible; the message says why."""


@dataclass(frozen=True)
class ReferencePoint:
    """A knob angle and the tip angle it gives (design assumption 1: other knob at 0 deg)."""

    knob_deg: float
    tip_deg: float


DEFAULT_HANDLE_SLIP_DEG = 3.0
"""Handle slip of a data sheet written before it was a constant of the sheet."""


@dataclass(frozen=True)
class DeviceKnob:
    """Data-sheet constants of one knob."""

    omega: float
    reference_pos: ReferencePoint
    reference_neg: ReferencePoint
    limits: KnobLimits
    release_omega: float | None = None
    """Optional, measured on the data-sheet unit only (`tsmd datasheet`): tip/knob slope of the
    release branches. No compensator uses it (it is that unit's, not the product's)."""
    reference_backlash_pos_deg: float | None = None
    """Optional: the data-sheet unit's tip backlash after the reversal at reference_pos
    (calibration compares its own backlash with it as a plausibility check)."""
    reference_backlash_neg_deg: float | None = None
    """Optional: the same after the reversal at reference_neg."""
    dead_zone_offset_deg: float | None = None
    """Optional: on the data-sheet unit, how far beyond the current's edge the tip leaves the
    plateau. Informational: no compensator uses it."""
    reference_dead_zone_pos_deg: float | None = None
    """Optional (with ``_neg``): the dead-zone edges tsmd's calibration found in the current of
    the unit the reference points were measured on (other knob at 0): the plateau heights are
    then product constants and each unit's loaded line moves with its own edges (method ours)."""
    reference_dead_zone_neg_deg: float | None = None
    handle_slip_deg: float = DEFAULT_HANDLE_SLIP_DEG
    """Knob travel over which the handle's static friction fades to kinetic after a restart
    (the online estimator models it; a sheet without it gets the default)."""
    reference_backlash_gain: float | None = None
    """Optional: the data-sheet unit's backlash gain beta (mean of both sides) from its own
    sweep current (other knob at 0): method ours scales omega per unit by ``1 - beta``."""
    backlash_settle_fraction: float | None = None
    """Optional: on the data-sheet unit, the share of its swing after a reversal that the motor
    current has made up when the tip starts back (the end of the backlash). Per product: where
    it is below :data:`tsmd.calibration.options.SETTLED_FRACTION`, calibration ends the backlash
    at this share instead of where the current has settled (old sheets: the settle rule)."""


@dataclass(frozen=True)
class DeviceModel:
    """Data-sheet constants of a catheter type (omega, reference points, limits)."""

    device_model: str
    knobs: tuple[DeviceKnob, DeviceKnob]
    description: str = ""
    schema_version: int = DEVICE_SCHEMA_VERSION

    @property
    def limits(self) -> tuple[KnobLimits, KnobLimits]:
        return (self.knobs[0].limits, self.knobs[1].limits)


@dataclass(frozen=True)
class KnobProfile:
    """What calibration identified for one knob, over the other knob's angle."""

    omega: float
    reference_pos: ReferencePoint
    reference_neg: ReferencePoint
    height_pos_deg: float
    height_neg_deg: float
    other_knob_deg: tuple[float, ...]
    dead_zone_pos_deg: tuple[float, ...]
    dead_zone_neg_deg: tuple[float, ...]
    backlash_pos_deg: tuple[float, ...]
    backlash_neg_deg: tuple[float, ...]
    tension_play: TensionPlayParams | None = None
    """The parameters of method ``ours`` (None: calibrated by an older tsmd)."""

    def grid_array(self) -> np.ndarray:
        """(n, 4) array: D_pos, D_neg, B_pos, B_neg per grid point."""
        return np.column_stack([self.dead_zone_pos_deg, self.dead_zone_neg_deg,
                                self.backlash_pos_deg, self.backlash_neg_deg]).astype(float)


@dataclass(frozen=True)
class CatheterProfile:
    """One catheter's calibration: everything the compensators need."""

    catheter_id: str
    device_model: str
    calibrated_at: str
    software_version: str
    interpolation: str
    knobs: tuple[KnobProfile, KnobProfile]
    source: str = "calibration"
    quality: dict[str, float] = field(default_factory=dict)
    schema_version: int = PROFILE_SCHEMA_VERSION


# ----------------------------------------------------------------------------------------------
# Validation helpers: each names the key path and the reason.


class _Reader:
    def __init__(self, origin: str) -> None:
        self.origin = origin

    def fail(self, key: str, reason: str) -> ProfileError:
        return ProfileError(f"{self.origin}: {key}: {reason}")

    def mapping(self, data: Any, key: str) -> Mapping[str, Any]:
        if not isinstance(data, Mapping):
            raise self.fail(key, f"must be a mapping, got {type(data).__name__}")
        return data

    def get(self, data: Mapping[str, Any], name: str, path: str) -> Any:
        if name not in data:
            raise self.fail(f"{path}{name}", "missing key")
        return data[name]

    def number(self, value: Any, key: str, lo: float | None = None, hi: float | None = None,
               unit: str = "") -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(key, f"must be a number{' in ' + unit if unit else ''}, got {value!r}")
        v = float(value)
        if math.isnan(v):
            raise self.fail(key, "is NaN")
        if math.isinf(v):
            raise self.fail(key, "is infinite")
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            raise self.fail(key, f"{v} {unit} is outside the plausible range [{lo}, {hi}]".replace(
                "  ", " "))
        return v

    def text(self, value: Any, key: str) -> str:
        if not isinstance(value, str) or not value.strip():
            raise self.fail(key, f"must be a non-empty string, got {value!r}")
        return value

    def numbers(self, value: Any, key: str, n: int | None, lo: float, hi: float,
                unit: str) -> tuple[float, ...]:
        if not isinstance(value, Sequence) or isinstance(value, str):
            raise self.fail(key, f"must be a list of numbers, got {type(value).__name__}")
        if n is not None and len(value) != n:
            raise self.fail(key, f"must have {n} values (one per grid point), got {len(value)}")
        return tuple(self.number(v, f"{key}[{i}]", lo, hi, unit) for i, v in enumerate(value))

    def version(self, data: Mapping[str, Any], supported: int) -> int:
        v = self.get(data, "schema_version", "")
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.fail("schema_version", f"must be an integer, got {v!r}")
        if v != supported:
            raise self.fail("schema_version",
                            f"unknown schema version {v} (this tsmd reads version {supported})")
        return v

    def reference(self, data: Any, key: str) -> ReferencePoint:
        m = self.mapping(data, key)
        return ReferencePoint(
            self.number(self.get(m, "knob_deg", key + "."), key + ".knob_deg",
                        -ANGLE_RANGE_DEG, ANGLE_RANGE_DEG, "deg"),
            self.number(self.get(m, "tip_deg", key + "."), key + ".tip_deg",
                        -ANGLE_RANGE_DEG, ANGLE_RANGE_DEG, "deg"))

    def omega(self, value: Any, key: str) -> float:
        return self.number(value, key, OMEGA_RANGE[0], OMEGA_RANGE[1], "tip deg per knob deg")

    def knob_map(self, data: Mapping[str, Any], path: str) -> list[tuple[str, Any]]:
        knobs = self.mapping(self.get(data, "knobs", path), path + "knobs")
        for name in knobs:
            if name not in KNOB_NAMES:
                raise self.fail(f"{path}knobs.{name}", f"unknown knob (expected {KNOB_NAMES})")
        return [(name, self.get(knobs, name, f"{path}knobs.")) for name in KNOB_NAMES]


def _check_references(r: _Reader, key: str, pos: ReferencePoint, neg: ReferencePoint) -> None:
    if not (pos.knob_deg > 0 > neg.knob_deg):
        raise r.fail(key, "reference_pos.knob_deg must be > 0 and reference_neg.knob_deg < 0")
    if not pos.tip_deg > neg.tip_deg:
        raise r.fail(key, "reference_pos.tip_deg must be above reference_neg.tip_deg")


# ----------------------------------------------------------------------------------------------
# Device model


def device_model_from_mapping(data: Any, origin: str = "device model") -> DeviceModel:
    r = _Reader(origin)
    m = r.mapping(data, "top level")
    version = r.version(m, DEVICE_SCHEMA_VERSION)
    name = r.text(r.get(m, "device_model", ""), "device_model")
    knobs: list[DeviceKnob] = []
    for knob_name, raw in r.knob_map(m, ""):
        key = f"knobs.{knob_name}"
        k = r.mapping(raw, key)
        lim = r.mapping(r.get(k, "limits", key + "."), key + ".limits")
        lk = key + ".limits."
        try:
            limits = KnobLimits(
                r.number(r.get(lim, "min_deg", lk), lk + "min_deg", -ANGLE_RANGE_DEG, 0, "deg"),
                r.number(r.get(lim, "max_deg", lk), lk + "max_deg", 0, ANGLE_RANGE_DEG, "deg"),
                r.number(r.get(lim, "max_velocity_deg_s", lk), lk + "max_velocity_deg_s",
                         1e-3, 1e4, "deg/s"),
                r.number(r.get(lim, "max_accel_deg_s2", lk), lk + "max_accel_deg_s2",
                         1e-3, 1e6, "deg/s^2"))
        except ValueError as exc:
            if isinstance(exc, ProfileError):
                raise
            raise r.fail(key + ".limits", str(exc)) from None
        pos = r.reference(r.get(k, "reference_pos", key + "."), key + ".reference_pos")
        neg = r.reference(r.get(k, "reference_neg", key + "."), key + ".reference_neg")
        _check_references(r, key, pos, neg)
        release = k.get("release_omega")
        b_pos, b_neg = k.get("reference_backlash_pos_deg"), k.get("reference_backlash_neg_deg")
        if len({release is None, b_pos is None, b_neg is None}) > 1:
            raise r.fail(key, "release_omega, reference_backlash_pos_deg and "
                         "reference_backlash_neg_deg go together (all or none)")

        def optional(value: Any, name: str, lo: float, hi: float, unit: str,
                     where: str = key) -> float | None:
            return None if value is None else r.number(value, f"{where}.{name}", lo, hi, unit)

        knobs.append(DeviceKnob(
            r.omega(r.get(k, "omega", key + "."), key + ".omega"), pos, neg, limits,
            None if release is None else r.omega(release, key + ".release_omega"),
            optional(b_pos, "reference_backlash_pos_deg", 0.0, 90.0, "deg"),
            optional(b_neg, "reference_backlash_neg_deg", 0.0, 90.0, "deg"),
            optional(k.get("dead_zone_offset_deg"), "dead_zone_offset_deg", -20.0, 20.0, "deg"),
            optional(k.get("reference_dead_zone_pos_deg"), "reference_dead_zone_pos_deg", 0.0,
                     90.0, "deg"),
            optional(k.get("reference_dead_zone_neg_deg"), "reference_dead_zone_neg_deg", -90.0,
                     0.0, "deg"),
            r.number(k.get("handle_slip_deg", DEFAULT_HANDLE_SLIP_DEG), key + ".handle_slip_deg",
                     0.01, 45.0, "deg"),
            optional(k.get("reference_backlash_gain"), "reference_backlash_gain", 0.0, 0.8, ""),
            optional(k.get("backlash_settle_fraction"), "backlash_settle_fraction", 0.5, 1.0,
                     "")))
    desc = m.get("description", "")
    return DeviceModel(name, (knobs[0], knobs[1]), str(desc), version)


def device_model_to_mapping(device: DeviceModel) -> dict[str, Any]:
    knobs: dict[str, Any] = {}
    for name, k in zip(KNOB_NAMES, device.knobs, strict=True):
        knobs[name] = {
            "omega": k.omega,
            "reference_pos": _ref_map(k.reference_pos),
            "reference_neg": _ref_map(k.reference_neg),
            "limits": {"min_deg": k.limits.min_deg, "max_deg": k.limits.max_deg,
                       "max_velocity_deg_s": k.limits.max_velocity_deg_s,
                       "max_accel_deg_s2": k.limits.max_accel_deg_s2},
        }
        if k.release_omega is not None:
            knobs[name]["release_omega"] = k.release_omega
            knobs[name]["reference_backlash_pos_deg"] = k.reference_backlash_pos_deg
            knobs[name]["reference_backlash_neg_deg"] = k.reference_backlash_neg_deg
        if k.dead_zone_offset_deg is not None:
            knobs[name]["dead_zone_offset_deg"] = k.dead_zone_offset_deg
        for key in ("reference_dead_zone_pos_deg", "reference_dead_zone_neg_deg"):
            if getattr(k, key) is not None:
                knobs[name][key] = getattr(k, key)
        knobs[name]["handle_slip_deg"] = k.handle_slip_deg
        if k.reference_backlash_gain is not None:
            knobs[name]["reference_backlash_gain"] = k.reference_backlash_gain
        if k.backlash_settle_fraction is not None:
            knobs[name]["backlash_settle_fraction"] = k.backlash_settle_fraction
    return {"schema_version": device.schema_version, "device_model": device.device_model,
            "description": device.description, "knobs": knobs}


def load_device_model(path: str | os.PathLike[str]) -> DeviceModel:
    """Read and validate a device model (data-sheet constants) from YAML."""
    return device_model_from_mapping(_read_yaml(Path(path)), str(path))


# ----------------------------------------------------------------------------------------------
# Profile


def _ref_map(p: ReferencePoint) -> dict[str, float]:
    return {"knob_deg": p.knob_deg, "tip_deg": p.tip_deg}


def _knob_from_mapping(r: _Reader, raw: Any, key: str) -> KnobProfile:
    k = r.mapping(raw, key)
    p = key + "."
    omega = r.omega(r.get(k, "omega", p), p + "omega")
    pos = r.reference(r.get(k, "reference_pos", p), p + "reference_pos")
    neg = r.reference(r.get(k, "reference_neg", p), p + "reference_neg")
    _check_references(r, key, pos, neg)
    h_pos = r.number(r.get(k, "height_pos_deg", p), p + "height_pos_deg", -90, 90, "deg")
    h_neg = r.number(r.get(k, "height_neg_deg", p), p + "height_neg_deg", -90, 90, "deg")
    grid = r.numbers(r.get(k, "other_knob_deg", p), p + "other_knob_deg", None,
                     -ANGLE_RANGE_DEG, ANGLE_RANGE_DEG, "deg")
    if len(grid) < 2:
        raise r.fail(p + "other_knob_deg", "needs at least two grid points")
    if any(b <= a for a, b in itertools.pairwise(grid)):
        raise r.fail(p + "other_knob_deg", f"grid is not sorted strictly increasing: {list(grid)}")
    n = len(grid)
    d_pos = r.numbers(r.get(k, "dead_zone_pos_deg", p), p + "dead_zone_pos_deg", n, 0, 90, "deg")
    d_neg = r.numbers(r.get(k, "dead_zone_neg_deg", p), p + "dead_zone_neg_deg", n, -90, 0, "deg")
    b_pos = r.numbers(r.get(k, "backlash_pos_deg", p), p + "backlash_pos_deg", n, 0, 90, "deg")
    b_neg = r.numbers(r.get(k, "backlash_neg_deg", p), p + "backlash_neg_deg", n, 0, 90, "deg")
    if k.get("ours") is not None:
        _log.warning("%s: %sours: parameters of the former 'ours' compensator ignored "
                     "(recalibrate for method 'ours')", r.origin, p)
    tension = None
    if k.get("tension_play") is not None:
        try:
            tension = tension_play_from_mapping(r.mapping(k["tension_play"], p + "tension_play"))
        except ValueError as exc:
            raise r.fail(p + "tension_play", str(exc)) from None
    return KnobProfile(omega, pos, neg, h_pos, h_neg, grid, d_pos, d_neg, b_pos, b_neg, tension)


def profile_from_mapping(data: Any, origin: str = "profile") -> CatheterProfile:
    """Validate a parsed YAML document and build the profile (ProfileError on any problem)."""
    r = _Reader(origin)
    m = r.mapping(data, "top level")
    version = r.version(m, PROFILE_SCHEMA_VERSION)
    catheter_id = r.text(r.get(m, "catheter_id", ""), "catheter_id")
    if not _ID_PATTERN.match(catheter_id):
        raise r.fail("catheter_id", f"{catheter_id!r} must be letters, digits, '.', '_' or '-'")
    device = r.text(r.get(m, "device_model", ""), "device_model")
    calibrated_at = r.text(str(r.get(m, "calibrated_at", "")), "calibrated_at")
    software = r.text(r.get(m, "software_version", ""), "software_version")
    method = r.get(m, "interpolation", "")
    if method not in INTERPOLATION_METHODS:
        raise r.fail("interpolation", f"{method!r} is not one of {list(INTERPOLATION_METHODS)}")
    source = str(m.get("source", "calibration"))
    quality_raw = r.mapping(m.get("quality", {}) or {}, "quality")
    quality = {str(q): r.number(v, f"quality.{q}") for q, v in quality_raw.items()}
    knobs = [_knob_from_mapping(r, raw, f"knobs.{name}") for name, raw in r.knob_map(m, "")]
    return CatheterProfile(catheter_id, device, calibrated_at, software, method,
                           (knobs[0], knobs[1]), source, quality, version)


def profile_to_mapping(profile: CatheterProfile) -> dict[str, Any]:
    knobs: dict[str, Any] = {}
    for name, k in zip(KNOB_NAMES, profile.knobs, strict=True):
        entry: dict[str, Any] = {
            "omega": k.omega,
            "reference_pos": _ref_map(k.reference_pos),
            "reference_neg": _ref_map(k.reference_neg),
            "height_pos_deg": k.height_pos_deg,
            "height_neg_deg": k.height_neg_deg,
            "other_knob_deg": list(k.other_knob_deg),
            "dead_zone_pos_deg": list(k.dead_zone_pos_deg),
            "dead_zone_neg_deg": list(k.dead_zone_neg_deg),
            "backlash_pos_deg": list(k.backlash_pos_deg),
            "backlash_neg_deg": list(k.backlash_neg_deg),
        }
        if k.tension_play is not None:
            entry["tension_play"] = tension_play_to_mapping(k.tension_play)
        knobs[name] = entry
    return {
        "schema_version": profile.schema_version,
        "catheter_id": profile.catheter_id,
        "device_model": profile.device_model,
        "calibrated_at": profile.calibrated_at,
        "software_version": profile.software_version,
        "source": profile.source,
        "interpolation": profile.interpolation,
        "quality": dict(profile.quality),
        "knobs": knobs,
    }


def _plain(obj: Any) -> Any:
    """numpy scalars -> Python floats so the YAML stays readable by safe_load."""
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


def _read_yaml(path: Path) -> Any:
    return read_yaml(path, ProfileError)


def load_profile(path: str | os.PathLike[str]) -> CatheterProfile:
    """Read and validate a catheter profile; any defect of the file is one ProfileError line."""
    data = _read_yaml(Path(path))
    try:
        return profile_from_mapping(data, str(path))
    except RecursionError:
        raise ProfileError(f"{path}: nested too deeply to be a profile") from None


def dump_profile(profile: CatheterProfile) -> str:
    header = (f"# tsmd catheter profile, schema version {profile.schema_version}\n"
              f"# source: {profile.source}\n")
    return header + yaml.safe_dump(_plain(profile_to_mapping(profile)), sort_keys=False,
                                   default_flow_style=None, width=100)


def save_profile(profile: CatheterProfile, path: str | os.PathLike[str]) -> None:
    """Write atomically: temp file in the same directory, fsync, keep the old file as .bak,
    rename over, fsync the directory. A crash at any point leaves a complete profile on disk."""
    target = Path(path)
    text = dump_profile(profile)
    profile_from_mapping(yaml.safe_load(text), str(target))  # never write what we cannot read
    _write_atomically(target, text)


def save_device_model(device: DeviceModel, path: str | os.PathLike[str],
                      comment: str = "") -> None:
    """Write a data sheet atomically (as :func:`save_profile`), ``comment`` as its YAML header."""
    target = Path(path)
    header = "".join(f"# {line}\n".replace("# \n", "#\n") for line in comment.splitlines())
    text = header + yaml.safe_dump(_plain(device_model_to_mapping(device)), sort_keys=False,
                                   allow_unicode=True)
    device_model_from_mapping(yaml.safe_load(text), str(target))  # never write what we cannot read
    _write_atomically(target, text)


def _write_atomically(target: Path, text: str) -> None:
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        if target.exists():
            backup = target.with_name(target.name + ".bak")
            # A hard link keeps the old file under the backup name while the target name
            # still points at it; replace() then swaps the target in one step.
            with contextlib.suppress(FileNotFoundError):
                backup.unlink()
            try:
                os.link(target, backup)
            except OSError:  # no hard links on this file system: copy instead
                shutil.copy2(target, backup)
        os.replace(tmp_name, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp_name)
        raise
    _fsync_dir(target.parent)


def _fsync_dir(directory: Path) -> None:
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


class ProfileStore:
    """Profiles kept as ``<dir>/<catheter_id>.yaml``."""

    def __init__(self, directory: str | os.PathLike[str]) -> None:
        self.directory = Path(directory)

    def path(self, catheter_id: str) -> Path:
        if not _ID_PATTERN.match(catheter_id):
            raise ProfileError(
                f"catheter id {catheter_id!r} must be letters, digits, '.', '_' or '-'")
        return self.directory / f"{catheter_id}.yaml"

    def load(self, catheter_id: str) -> CatheterProfile:
        path = self.path(catheter_id)
        if not path.exists():
            raise ProfileError(f"no profile for catheter {catheter_id!r} in {self.directory}")
        profile = load_profile(path)
        # <id>.<version>.yaml (e.g. an online re-estimate) is a version of catheter <id>
        if profile.catheter_id != catheter_id \
                and not catheter_id.startswith(profile.catheter_id + "."):
            raise ProfileError(f"{path}: catheter_id is {profile.catheter_id!r}, "
                               f"expected {catheter_id!r}")
        return profile

    def save(self, profile: CatheterProfile) -> Path:
        path = self.path(profile.catheter_id)
        save_profile(profile, path)
        return path

    def list(self) -> list[str]:
        if not self.directory.is_dir():
            return []
        return sorted(p.stem for p in self.directory.glob("*.yaml")
                      if _ID_PATTERN.match(p.stem) and p.is_file())


def standard_grid() -> tuple[float, ...]:
    """The paper's calibration grid of the other knob's angle."""
    return CALIBRATION_GRID_DEG


def make_knob_profile(device_knob: DeviceKnob, other_knob_deg: Sequence[float],
                      dead_zone_pos_deg: Sequence[float], dead_zone_neg_deg: Sequence[float],
                      backlash_pos_deg: Sequence[float], backlash_neg_deg: Sequence[float],
                      tension_play: TensionPlayParams | None = None) -> KnobProfile:
    """A knob's profile from identified grids and the data sheet.

    H_pos/H_neg follow design assumptions 1-3: the line of slope omega through the reference point
    (other knob at 0 deg) meets the dead-zone edge D(0) at height H; H is then constant.
    """
    k = device_knob
    h_pos, h_neg = plateau_heights(k, at_other_knob_zero(other_knob_deg, dead_zone_pos_deg),
                                   at_other_knob_zero(other_knob_deg, dead_zone_neg_deg))

    def floats(values: Sequence[float]) -> tuple[float, ...]:
        return tuple(float(v) for v in values)

    return KnobProfile(k.omega, k.reference_pos, k.reference_neg, float(h_pos), float(h_neg),
                       floats(other_knob_deg), floats(dead_zone_pos_deg),
                       floats(dead_zone_neg_deg), floats(backlash_pos_deg),
                       floats(backlash_neg_deg), tension_play)
