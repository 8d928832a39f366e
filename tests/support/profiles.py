"""A complete catheter profile on the simulated device's data sheet, for the tests."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from tsmd.compensation.tension_play_params import TensionPlayParams
from tsmd.profile import (
    CatheterProfile,
    KnobProfile,
    ProfileError,
    device_model_from_mapping,
    device_model_to_mapping,
    load_device_model,
    make_knob_profile,
)

ROOT = Path(__file__).resolve().parents[2]
DEVICE = ROOT / "profiles" / "devices" / "sim-catheter.yaml"
GRID = (-90.0, -60.0, -30.0, 0.0, 30.0, 60.0, 90.0)


def with_tension_play(k: KnobProfile, backlash_gain: float = 0.3,
                      zero_load_inset_deg: float = 8.0) -> KnobProfile:
    """``k`` with tension-play parameters on its own edges and heights (method ``ours``)."""
    n = len(k.other_knob_deg)
    return dataclasses.replace(k, tension_play=TensionPlayParams(
        k.omega, k.height_pos_deg, k.height_neg_deg, k.other_knob_deg, k.dead_zone_pos_deg,
        k.dead_zone_neg_deg, (backlash_gain,) * n, (backlash_gain,) * n,
        tuple(d - zero_load_inset_deg for d in k.dead_zone_pos_deg),
        tuple(d + zero_load_inset_deg for d in k.dead_zone_neg_deg)))


def make_profile(catheter_id: str = "sim-001", d0: float = 20.0) -> CatheterProfile:
    device = load_device_model(DEVICE)
    knobs = tuple(
        with_tension_play(make_knob_profile(k, GRID, [d0 - abs(g) / 30 for g in GRID],
                                            [-d0 + abs(g) / 30 for g in GRID], [15.0] * 7,
                                            [16.0] * 7))
        for k in device.knobs)
    return CatheterProfile(catheter_id, device.device_model, "2026-11-22T03:00:00Z",
                           "tsmd 0.1.0", "pchip", (knobs[0], knobs[1]),
                           quality={"cycle_agreement_deg": 0.4})


def assert_sheet_knob_field_round_trips(name: str, knob: int, value: float, outside: float
                                        ) -> None:
    """An optional per-knob data-sheet field: set on ``knob`` alone it loads there and nowhere
    else, is written back only there, and ``outside`` its range is refused naming the key."""
    knob_key, other_key = ("phi1", "phi2") if knob == 0 else ("phi2", "phi1")
    data = device_model_to_mapping(load_device_model(DEVICE))
    data["knobs"][knob_key][name] = value
    data["knobs"][other_key].pop(name, None)
    device = device_model_from_mapping(data)
    assert getattr(device.knobs[knob], name) == value
    assert getattr(device.knobs[1 - knob], name) is None
    written = device_model_to_mapping(device)["knobs"]
    assert written[knob_key][name] == value
    assert name not in written[other_key]
    data["knobs"][knob_key][name] = outside
    with pytest.raises(ProfileError, match=rf"knobs.{knob_key}.{name}"):
        device_model_from_mapping(data)
