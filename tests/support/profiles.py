"""A complete catheter profile on the simulated device's data sheet, for the tests."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from tsmd.compensation.tension_play import TensionPlayParams
from tsmd.profile import CatheterProfile, KnobProfile, load_device_model, make_knob_profile

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
