"""The product's dead-zone edge reader (data-sheet ``edge_rise``, ``tsmd datasheet
--edge-rise``): a sheet that says so has every unit's edges read where the current starts to
rise (``IdentifyOptions.edge = "rise"``); without it the edge is fitted as before."""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import pytest

from tsmd.calibration.options import device_options
from tsmd.commands.datasheet_args import add_arguments
from tsmd.errors import TsmdError
from tsmd.profile import DeviceModel
from tsmd.profile.files import load_device_model
from tsmd.profile.sheet_schema import device_model_from_mapping, device_model_to_mapping

SHEET = Path(__file__).parents[1] / "profiles/devices/family/warmgear.yaml"


def _with_edge_rise(on: tuple[bool | None, bool | None]) -> DeviceModel:
    device = load_device_model(SHEET)
    knobs = tuple(replace(k, edge_rise=o) for k, o in zip(device.knobs, on, strict=True))
    return replace(device, knobs=(knobs[0], knobs[1]))


def test_a_knob_with_edge_rise_reads_its_edges_where_the_current_starts_to_rise() -> None:
    phi1, phi2 = device_options(None, _with_edge_rise((True, None)))
    assert phi1.edge == "rise"
    assert phi2.edge == "fit"


def test_edge_rise_keeps_the_rest_of_the_knobs_identification() -> None:
    plain = device_options(None, _with_edge_rise((None, None)))[0]
    rise = device_options(None, _with_edge_rise((True, None)))[0]
    assert replace(rise, edge=plain.edge) == plain


def test_the_sheet_carries_edge_rise_per_knob() -> None:
    read = device_model_from_mapping(device_model_to_mapping(_with_edge_rise((True, True))))
    assert [k.edge_rise for k in read.knobs] == [True, True]


def test_a_sheet_without_edge_rise_writes_no_such_field() -> None:
    data = device_model_to_mapping(_with_edge_rise((None, None)))
    assert all("edge_rise" not in k for k in data["knobs"].values())


def test_edge_rise_must_be_true_or_false() -> None:
    data = device_model_to_mapping(_with_edge_rise((None, None)))
    data["knobs"]["phi2"]["edge_rise"] = "rise"
    with pytest.raises(TsmdError, match="edge_rise"):
        device_model_from_mapping(data)


def test_datasheet_takes_the_edge_reader_as_a_flag() -> None:
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    base = ["--plant", "m:f", "--out", "x.yaml"]
    assert parser.parse_args([*base, "--edge-rise"]).edge_rise is True
    assert parser.parse_args(base).edge_rise is False
