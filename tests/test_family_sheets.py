"""The family's shipped data sheets stay loadable and name the plant they were measured on."""

from __future__ import annotations

from pathlib import Path

import pytest

from simrig.family import PLANT_SPECS
from tsmd.config import PACKAGE_ROOT
from tsmd.profile import load_device_model

SHEETS = sorted((PACKAGE_ROOT / "profiles" / "devices" / "family").glob("*.yaml"))


def test_every_family_plant_but_the_development_one_ships_a_sheet() -> None:
    """Capstan's sheet is the packaged default, profiles/devices/sim-catheter.yaml."""
    assert {p.stem for p in SHEETS} == set(PLANT_SPECS) - {"capstan"}


@pytest.mark.parametrize("path", SHEETS, ids=lambda p: p.stem)
def test_family_sheet_loads_and_names_its_plant(path: Path) -> None:
    sheet = load_device_model(path)
    assert sheet.device_model == f"family-{path.stem}"
    assert len(sheet.knobs) == 2
