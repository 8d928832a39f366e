"""The strict dataclass loader: every key known, typed and range-checked, errors name the path."""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest

from tsmd.strict_dataclass import SchemaError, build_dataclass


@dataclass(frozen=True)
class _Inner:
    gain: float = field(default=1.0, metadata={"range": (0.0, 2.0)})


@dataclass(frozen=True)
class _Outer:
    name: str
    inner: _Inner = field(default_factory=_Inner)
    labels: list[str] = field(default_factory=list)


def test_builds_nested_dataclasses_and_converts_integers_to_floats() -> None:
    built = build_dataclass(_Outer, {"name": "a", "inner": {"gain": 2}})
    assert built == _Outer(name="a", inner=_Inner(gain=2.0))
    assert isinstance(built.inner.gain, float)


def test_unknown_key_is_refused_with_its_path_and_the_known_keys() -> None:
    with pytest.raises(SchemaError, match=r"inner\.gian: unknown key \(known keys: gain\)"):
        build_dataclass(_Outer, {"name": "a", "inner": {"gian": 1.0}})


def test_value_out_of_range_is_refused_with_its_path() -> None:
    with pytest.raises(SchemaError, match=r"inner\.gain: 3\.0 is out of range \[0\.0, 2\.0\]"):
        build_dataclass(_Outer, {"name": "a", "inner": {"gain": 3.0}})


def test_missing_required_key_is_named() -> None:
    with pytest.raises(SchemaError, match=r"^name: missing \(required\)"):
        build_dataclass(_Outer, {})


def test_wrong_item_type_names_the_list_index() -> None:
    with pytest.raises(SchemaError, match=r"labels\[1\]: expected a string"):
        build_dataclass(_Outer, {"name": "a", "labels": ["x", 2]})


def test_non_finite_number_is_refused() -> None:
    with pytest.raises(SchemaError, match="must be a finite number"):
        build_dataclass(_Outer, {"name": "a", "inner": {"gain": float("nan")}})
