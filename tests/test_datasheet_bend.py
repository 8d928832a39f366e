"""`tsmd datasheet --bend-relation`: the product's bend relation from the sheet's unit."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import pytest
from support.profiles import DEVICE
from test_online_bend import bent_by, fake_profile

from tsmd.calibration.errors import CalibrationRefusedError
from tsmd.config import default_sim_config
from tsmd.datasheet_bend import bend_relation, rig_calibration, sheet_with_bend
from tsmd.errors import TsmdError
from tsmd.online.bend import BendRelation, sheet_bend_relation, with_bend_relation
from tsmd.profile import device_model_from_mapping, device_model_to_mapping, load_device_model


def test_the_relation_comes_from_the_unit_straight_and_bent_leaving_out_a_refused_bend() -> None:
    asked: list[float] = []

    def calibrate_bent(bend_deg: float) -> Any:
        asked.append(bend_deg)
        if bend_deg == 90.0:
            raise CalibrationRefusedError("refused", [])
        return fake_profile(20.0, 5.0, 0.3) if bend_deg == 0.0 else bent_by(
            bend_deg / 10.0, bend_deg / 12.0, 1.0 + 0.006 * bend_deg)

    relation = bend_relation(calibrate_bent)
    assert asked == [0.0, 30.0, 60.0, 90.0]
    assert relation.release_per_edge == pytest.approx(1.2)
    assert relation.gain_per_release_deg == pytest.approx(0.06)


def test_a_sheet_written_with_the_relation_gives_it_back() -> None:
    device = with_bend_relation(load_device_model(DEVICE), BendRelation(1.16789, 0.06312))
    again = device_model_from_mapping(device_model_to_mapping(device))
    assert sheet_bend_relation(again) == BendRelation(1.168, 0.0631)


def test_a_plant_that_cannot_bend_is_refused_in_one_line() -> None:
    run = rig_calibration(lambda: SimpleNamespace(), load_device_model(DEVICE),  # type: ignore[arg-type,return-value]
                          default_sim_config())
    with pytest.raises(TsmdError, match="--bend-relation: .*cannot change shape") as err:
        run(30.0)
    assert "\n" not in str(err.value)


def test_a_product_whose_bends_move_no_edge_keeps_its_sheet_without_a_relation() -> None:
    device = load_device_model(DEVICE)
    kept, line = sheet_with_bend(device, lambda bend_deg: fake_profile(20.0, 5.0, 0.3))
    assert kept == device and sheet_bend_relation(kept) is None
    assert line.startswith("no bend relation on the sheet") and "\n" not in line


def test_the_sheet_gets_the_relation_its_bends_give() -> None:
    def calibrate_bent(bend_deg: float) -> Any:
        return fake_profile(20.0, 5.0, 0.3) if bend_deg == 0.0 else bent_by(
            bend_deg / 10.0, bend_deg / 12.0, 1.0 + 0.006 * bend_deg)

    device, line = sheet_with_bend(load_device_model(DEVICE), calibrate_bent)
    assert sheet_bend_relation(device) == BendRelation(1.2, 0.06)
    assert line.startswith("bend relation on the sheet's unit")
