"""The data sheet's coupling of the tip planes (tsmd.datasheet_coupling): the plateau's middle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tsmd.datasheet_coupling import plateau_middle_deg
from tsmd.errors import TsmdError


def play_sweep(offset_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """A +-90 deg sweep through a play: the tip stands at -3 rising and +3 falling inside the
    dead zone (+-20 deg), shifted by ``offset_deg``."""
    t = np.arange(0.0, 25.0, 0.004)
    knob = 90.0 * np.sin(2 * math.pi * 0.04 * t)
    rising = np.gradient(knob) > 0
    tip = np.where(rising, -3.0, 3.0) + np.where(np.abs(knob) > 20.0,
                                                 1.4 * (knob - 20.0 * np.sign(knob)), 0.0)
    return knob, tip + offset_deg


@pytest.mark.parametrize("offset_deg", [-6.9, 0.0, 4.2])
def test_the_plateaus_middle_is_the_tips_offset_in_the_dead_zone(offset_deg: float) -> None:
    knob, tip = play_sweep(offset_deg)
    assert plateau_middle_deg(knob, tip, 20.0) == pytest.approx(offset_deg, abs=1e-9)


def test_a_sweep_that_does_not_cross_the_dead_zone_is_one_line() -> None:
    knob, tip = play_sweep(0.0)
    with pytest.raises(TsmdError, match="does not cross the dead zone") as err:
        plateau_middle_deg(0.5 * knob + 60.0, tip, 20.0)
    assert "\n" not in str(err.value)
