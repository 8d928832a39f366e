"""The data sheet's loaded-branch template (tsmd.datasheet_shape) on synthetic tracked sweeps."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tsmd.datasheet_shape import measure_loaded_shape

EDGE_DEG = 20.0
PLATEAU_DEG = -5.0
OMEGA = 1.4


def sweep(bend: float, noise_deg: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Two +-90 deg cycles of a knob; tip on the positive side: the plateau up to the edge,
    then OMEGA (u + bend u^2 / 140); the negative side is left flat (not read here)."""
    t = np.arange(0.0, 50.0, 0.004)
    pos = -90.0 * np.cos(2 * math.pi * 0.04 * t)
    u = np.maximum(pos - EDGE_DEG, 0.0)
    tip = PLATEAU_DEG + OMEGA * (u + bend * u * u / 140.0)
    rng = np.random.default_rng(0)
    return pos, tip + rng.normal(0.0, noise_deg, t.size)


def test_a_straight_branch_gives_the_identity() -> None:
    pos, tip = sweep(0.0)
    shape = measure_loaded_shape(pos, tip, EDGE_DEG, OMEGA, 1)
    assert shape is not None
    for u, t in zip(shape.travel_deg, shape.shaped_deg, strict=True):
        assert t == pytest.approx(u, abs=0.02)


@pytest.mark.parametrize("bend", [-0.4, 0.3])
def test_a_curved_branch_gives_its_shape(bend: float) -> None:
    pos, tip = sweep(bend, noise_deg=0.2)
    shape = measure_loaded_shape(pos, tip, EDGE_DEG, OMEGA, 1)
    assert shape is not None and shape.travel_deg[-1] > 60.0
    for u, t in zip(shape.travel_deg, shape.shaped_deg, strict=True):
        assert t == pytest.approx(u + bend * u * u / 140.0, abs=0.1)


def test_the_template_is_monotone_whatever_the_tip_does() -> None:
    pos, tip = sweep(0.0, noise_deg=0.2)
    tip = np.where(pos > 50.0, tip[np.argmin(np.abs(pos - 50.0))], tip)  # a tip that stalls
    shape = measure_loaded_shape(pos, tip, EDGE_DEG, OMEGA, 1)
    assert shape is not None
    assert all(np.diff(shape.shaped_deg) > 0) and all(np.diff(shape.travel_deg) > 0)


def test_a_side_never_loaded_from_the_dead_zone_gives_none() -> None:
    pos, tip = sweep(0.0)
    assert measure_loaded_shape(np.clip(pos, 30.0, None), tip, EDGE_DEG, OMEGA, 1) is None
