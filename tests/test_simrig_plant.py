"""Plants are plugged in from config as 'module:factory'."""

from __future__ import annotations

import pytest

from simrig.plant import PlantLoadError, load_plant


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("no_colon", "must look like"),
        ("nonexistent_module_xyz:f", "cannot import"),
        ("math:nope", "no callable"),
        ("math:sqrt", "rejected its parameters"),
    ],
)
def test_bad_plant_spec_is_named(spec: str, message: str) -> None:
    with pytest.raises(PlantLoadError, match=message):
        load_plant(spec, {"x": 1})


def test_factory_returning_non_plant_is_refused() -> None:
    with pytest.raises(PlantLoadError, match="not a Plant"):
        load_plant("builtins:dict", {})
