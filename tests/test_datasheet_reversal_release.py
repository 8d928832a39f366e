"""The product's release end per reversal read from the sheet unit's tip
(tsmd.datasheet_reversal_release) and carried by the data sheet."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tsmd.compensation.reversal_release import ReleaseEndShape
from tsmd.datasheet_reversal_release import (
    pass_release_line,
    shape_from_lines,
    sweep_release_line,
)
from tsmd.profile.device import DeviceModel
from tsmd.profile.sheet_schema import device_model_from_mapping, device_model_to_mapping


def release_pass(amplitude_deg: float, end_deg: float, slope: float = 1.5,
                 backlash_deg: float = 5.0) -> tuple[np.ndarray, np.ndarray]:
    """One pass from +A down to -A: held for the backlash, then a line to ``end_deg`` on the
    plateau at 0, flat, then the other side's loaded line from -25 deg."""
    x = np.linspace(amplitude_deg, -amplitude_deg, 2000)
    held = slope * (amplitude_deg - backlash_deg - end_deg)
    tip = np.clip(slope * (x - end_deg), 0.0, held) + np.minimum(x + 25.0, 0.0)
    return x, tip


def test_a_pass_release_end_is_where_its_line_meets_the_plateau() -> None:
    x, tip = release_pass(60.0, 27.0)
    end, slope = pass_release_line(x, tip) or (0.0, 0.0)
    assert end == pytest.approx(27.0, abs=0.05)
    assert slope == pytest.approx(1.5, abs=0.01)


def test_a_pass_without_a_release_has_no_end() -> None:
    x = np.linspace(20.0, -20.0, 500)
    assert pass_release_line(x, np.zeros_like(x)) is None


def test_a_sweep_reads_both_sides_mirrored() -> None:
    x, tip = release_pass(60.0, 27.0)
    pos = np.concatenate([x, -x, x])
    tips = np.concatenate([tip, -tip, tip])
    line = sweep_release_line(pos, tips, 60.0)
    assert line is not None and line[0] == pytest.approx(27.0, abs=0.05)


def test_the_shape_is_the_tips_line_over_the_models() -> None:
    tip = {45.0: (21.0, 0.9), 60.0: (27.0, 1.4), 75.0: None, 90.0: (30.0, 1.5)}
    model = {45.0: (30.0, 1.8), 60.0: (30.0, 1.75), 75.0: (30.0, 1.7), 90.0: (30.0, 1.5)}
    shape = shape_from_lines(tip, model)
    assert shape is not None
    assert shape.reversal_fraction == pytest.approx((0.5, 2.0 / 3.0, 1.0))
    assert shape.end_ratio == pytest.approx((0.7, 0.9, 1.0))
    assert shape.slope_ratio == pytest.approx((0.5, 0.8, 1.0))


def test_no_shape_where_no_amplitude_reads_on_both() -> None:
    assert shape_from_lines({90.0: (30.0, 1.5)}, {90.0: None}) is None


def test_a_sheet_carries_the_shape_and_one_without_writes_no_key(sim_device: DeviceModel) -> None:
    mapping = device_model_to_mapping(sim_device)
    assert all("release_end_shape" not in k for k in mapping["knobs"].values())
    shape = ReleaseEndShape((0.5, 1.0), (0.7, 1.0), (0.8, 0.9))
    knobs = (dataclasses.replace(sim_device.knobs[0], release_end_shape=shape), sim_device.knobs[1])
    shaped = dataclasses.replace(sim_device, knobs=knobs)
    back = device_model_from_mapping(device_model_to_mapping(shaped))
    assert back.knobs[0].release_end_shape == shape
    assert back.knobs[1].release_end_shape is None


def test_a_bad_shape_in_a_sheet_is_refused_naming_its_key(sim_device: DeviceModel) -> None:
    mapping = device_model_to_mapping(sim_device)
    mapping["knobs"]["phi2"]["release_end_shape"] = {"reversal_fraction": [1.0, 0.5],
                                                     "end_ratio": [1.0, 0.7],
                                                     "slope_ratio": [1.0, 1.0]}
    with pytest.raises(ValueError, match="phi2.release_end_shape"):
        device_model_from_mapping(mapping)
