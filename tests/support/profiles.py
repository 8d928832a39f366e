"""A complete catheter profile on the simulated device's data sheet, for the tests."""

from __future__ import annotations

from pathlib import Path

from tsmd.compensation.ours import OursParams
from tsmd.profile import CatheterProfile, load_device_model, make_knob_profile

ROOT = Path(__file__).resolve().parents[2]
DEVICE = ROOT / "profiles" / "devices" / "sim-catheter.yaml"
GRID = (-90.0, -60.0, -30.0, 0.0, 30.0, 60.0, 90.0)


def make_profile(catheter_id: str = "sim-001", d0: float = 20.0) -> CatheterProfile:
    device = load_device_model(DEVICE)
    knobs = tuple(
        make_knob_profile(k, GRID, [d0 - abs(g) / 30 for g in GRID],
                          [-d0 + abs(g) / 30 for g in GRID], [15.0] * 7, [16.0] * 7,
                          OursParams.pivot_at_dead_zone(k.omega, [20.0] * 7, [-20.0] * 7))
        for k in device.knobs)
    return CatheterProfile(catheter_id, device.device_model, "2026-11-22T03:00:00Z",
                           "tsmd 0.1.0", "pchip", (knobs[0], knobs[1]),
                           quality={"cycle_agreement_deg": 0.4})
