"""Fixtures shared by the test modules; fakes and helpers live in the ``support`` package."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from support.api import Stack, start_stack, stop_stack
from support.profiles import DEVICE

from tsmd.profile import DeviceModel, load_device_model


@pytest.fixture
def stack(tmp_path: Path) -> Iterator[Stack]:
    """The socket API on a fake loop, ticking in real time; stopped after the test."""
    s = start_stack(tmp_path)
    yield s
    stop_stack(s)


@pytest.fixture(scope="session")
def sim_device() -> DeviceModel:
    """The simulated catheter's data sheet (profiles/devices/sim-catheter.yaml)."""
    return load_device_model(DEVICE)
