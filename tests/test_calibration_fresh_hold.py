"""The fresh catheter's first-release hold from the calibration's first sweep (current only)."""

from __future__ import annotations

import dataclasses

import pytest

from simrig.family import family_member
from tsmd.calibration.fresh_hold import fresh_differences, fresh_hold_deg, with_fresh_hold
from tsmd.calibration.protocol import paper_protocol
from tsmd.calibration.run import run_sweeps
from tsmd.replay import LockstepRunner


@pytest.fixture(scope="module")
def first_sweep_twice():  # type: ignore[no-untyped-def]
    """The calibration's first sweep on a fresh capstan unit, then the same sweep again."""
    proto = paper_protocol()
    proto = dataclasses.replace(proto, sweeps=(proto.sweeps[0],))
    with LockstepRunner(None, None, "none", 3000, family_member("capstan", 1).build()) as runner:
        fresh = run_sweeps(runner, proto, live_loop=False).points[0]
        again = run_sweeps(runner, proto, live_loop=False).points[0]
    return fresh, again


def test_the_first_sweep_of_a_fresh_catheter_shows_a_hold(first_sweep_twice) -> None:  # type: ignore[no-untyped-def]
    fresh, again = first_sweep_twice
    assert fresh_hold_deg(fresh.result.data) > fresh_hold_deg(again.result.data) + 5.0


def test_a_sweep_on_a_loaded_catheter_gives_no_fresh_numbers(first_sweep_twice) -> None:  # type: ignore[no-untyped-def]
    _, again = first_sweep_twice
    assert fresh_differences(again.result.data) == (0.0, 0.0)


def test_only_the_knob_swept_first_gets_the_hold(first_sweep_twice) -> None:  # type: ignore[no-untyped-def]
    fresh, _ = first_sweep_twice
    fields = [("fresh_hold_deg", float), ("fresh_edge_delay_deg", float)]
    params = [dataclasses.make_dataclass("P", fields)(0.0, 0.0) for _ in (0, 1)]
    out = with_fresh_hold(params, [fresh])
    assert out[fresh.knob].fresh_hold_deg > 0.0
    assert out[1 - fresh.knob].fresh_hold_deg == 0.0
