"""tsmd.stack: one way from a configuration to a loop, its knob limits and its compensator."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from support.drives import FakeDrives
from support.profiles import make_profile

from drivers.clock import SimClock
from tsmd.compensation import NoCompensation
from tsmd.compensation.safety import KnobLimits
from tsmd.config import TsmdConfig, default_sim_config
from tsmd.profile import DeviceModel
from tsmd.stack import StackError, build_loop, knob_limits, make_compensator


def with_phi1_limits(config: TsmdConfig, **changes: float) -> TsmdConfig:
    limits = dataclasses.replace(config.limits,
                                 phi1=dataclasses.replace(config.limits.phi1, **changes))
    return dataclasses.replace(config, limits=limits)


def test_knob_limits_are_the_configured_ones() -> None:
    config = with_phi1_limits(default_sim_config(), min_deg=-60.0, max_velocity_deg_s=80.0)
    phi1, phi2 = knob_limits(config)
    assert (phi1.min_deg, phi1.max_deg, phi1.max_velocity_deg_s) == (-60.0, 90.0, 80.0)
    assert phi2 == KnobLimits(-90.0, 90.0, 120.0, 2000.0)


def test_limits_wider_than_the_data_sheet_are_refused_naming_the_knob(
        sim_device: DeviceModel) -> None:
    knob_limits(default_sim_config(), sim_device)  # the sim config fits its own data sheet
    narrow = dataclasses.replace(sim_device.knobs[0],
                                 limits=KnobLimits(-90.0, 90.0, 60.0, 2000.0))
    device = dataclasses.replace(sim_device, knobs=(narrow, sim_device.knobs[1]))
    with pytest.raises(StackError, match=r"limits\.phi1 .* data sheet of sim-catheter"):
        knob_limits(default_sim_config(), device)


def test_no_profile_gives_no_compensation_whatever_the_method() -> None:
    assert isinstance(make_compensator(None, "ours", default_sim_config()), NoCompensation)


def test_an_unknown_method_is_a_compensation_error() -> None:
    with pytest.raises(StackError, match="magic") as info:
        make_compensator(make_profile(), "magic", default_sim_config())
    assert info.value.code == "compensation"


def test_the_loop_clamps_to_the_configured_range_and_ticks_at_the_configured_period() -> None:
    config = with_phi1_limits(default_sim_config(), max_deg=45.0)
    clock = SimClock()
    loop = build_loop(config, FakeDrives(), NoCompensation(), clock, compensation_label="none",
                      after_sync=lambda: clock.advance(config.loop.period_s))
    assert loop.period_s == config.loop.period_s
    assert [r.max_deg for r in loop.ranges()] == [45.0, 90.0]
    loop.tick()
    loop.execute("enable")
    loop.setpoint.set((80.0, 0.0))
    for _ in range(200):
        sample = loop.tick()
    assert sample.q_deg[0] == 45.0
    assert np.isclose(sample.cmd_deg[0], 45.0)
