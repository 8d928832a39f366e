"""The settle rule's backlash ended the data sheet's lag later: on the sheet's unit the tip lets
go 0.6-1.0 deg of knob after the current has settled (docs/calibration.md, session 9)."""

from __future__ import annotations

from dataclasses import replace
from functools import cache

import numpy as np
import pytest

from tsmd.calibration.identify import analyse_half_cycle, settle_rule_backlash, split_half_cycles
from tsmd.calibration.options import SETTLED_FRACTION, IdentifyOptions, for_product
from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import HalfCycle


@cache
def _data() -> Conditioned:
    """Knob 60 -> 90 -> -90 deg, 10 samples per degree: after the reversal the current settles
    on its release level (a 3 deg decay), then loads again 120 deg on."""
    up = np.linspace(60.0, 90.0, 301)
    down = np.linspace(90.0, -90.0, 1801)[1:]
    pos = np.concatenate([up, down])
    travel = 90.0 - down
    after = -(0.1 - 1.1 * np.exp(-travel / 3.0) + 0.02 * np.maximum(travel - 120.0, 0.0))
    current = np.concatenate([np.linspace(0.9, 1.0, up.size), after])
    t = np.arange(pos.size) * 1e-2
    return Conditioned(t, pos, pos, current, current, 100.0, 0.001, 0.0005, ())


def _after_reversal(opts: IdentifyOptions) -> HalfCycle:
    data = _data()
    halves = [analyse_half_cycle(data, d, a, b, r, opts)
              for d, a, b, r in split_half_cycles(data.cmd_deg, 10.0) if r]
    assert len(halves) == 1
    return halves[0]


def test_a_settled_product_with_a_lag_keeps_the_settle_rule_and_takes_the_lag() -> None:
    opts = for_product(IdentifyOptions(), SETTLED_FRACTION + 0.005, 0.007, 0.8)
    assert opts.backlash == "settle"
    assert opts.backlash_settle_lag_deg == 0.8


def test_a_sheet_without_a_lag_ends_the_backlash_at_the_settle() -> None:
    assert for_product(IdentifyOptions(), 0.998, 0.007) == IdentifyOptions()


def test_the_lag_moves_the_settle_rules_backlash_end_by_itself() -> None:
    plain = _after_reversal(IdentifyOptions())
    lagged = _after_reversal(replace(IdentifyOptions(), backlash_settle_lag_deg=1.0))
    assert lagged.backlash_deg - plain.backlash_deg == pytest.approx(1.0, abs=0.25)
    assert lagged.backlash_end_index is not None and plain.backlash_end_index is not None
    assert lagged.backlash_end_index > plain.backlash_end_index


def test_the_tension_plays_settle_rule_backlash_ignores_the_lag() -> None:
    # its straight release line starts where the current has settled, whatever the tip does
    lagged = replace(IdentifyOptions(), backlash_settle_lag_deg=1.0)
    assert settle_rule_backlash(_data(), lagged) == settle_rule_backlash(_data())
