"""One validating reader of a YAML mapping: every defect becomes one :class:`ProfileError`
naming the document's origin, the key path and the reason (profiles and data sheets alike)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from tsmd.profile.device import ReferencePoint
from tsmd.profile.types import ANGLE_RANGE_DEG, KNOB_NAMES, OMEGA_RANGE, ProfileError


class Reader:
    """Reads one document (``origin`` names it in every error)."""

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
