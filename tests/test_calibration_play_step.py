"""A handle's play closing after a reversal (session 24): where the product's sheet chose it,
each backlash ends at the lone step of the flat current (tsmd.calibration.play_step); without
a clear step a half-cycle gives no backlash; without the sheet's choice nothing changes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from support.play_step import PLAY_DEG, SWING_DEG, sweep

from tsmd.calibration.identify import identify_sweep
from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.play_step import find_play_step
from tsmd.profile import load_device_model

SHEETS = Path(__file__).resolve().parents[1] / "profiles" / "devices" / "family"


def flat_with_step(step_A: float, at_deg: float = 20.0, seed: int = 0) -> np.ndarray:
    """60 deg of a flat current on a 0.25 deg grid with white noise (1 mA), stepping by
    ``step_A`` at ``at_deg``, after a 3 deg swing up from the reversal."""
    x = np.arange(0.0, 60.0, 0.25)
    y = 0.03 * np.minimum(x / SWING_DEG, 1.0) + step_A * (x >= at_deg)
    return y + np.random.default_rng(seed).normal(0.0, 0.001, x.size)


def test_a_lone_step_in_the_flat_current_is_found_where_it_is() -> None:
    found = find_play_step(flat_with_step(-0.010), 0.25)
    assert found is not None
    assert abs(found.index * 0.25 - 20.0) <= 0.5
    assert found.size_A < 0.0


def test_a_flat_current_with_noise_only_shows_no_step() -> None:
    assert find_play_step(flat_with_step(0.0), 0.25) is None


def test_a_step_within_the_noise_shows_none() -> None:
    assert find_play_step(flat_with_step(-0.0005), 0.25) is None


def test_the_search_ends_at_the_stop_given() -> None:
    assert find_play_step(flat_with_step(-0.010, at_deg=40.0), 0.25, stop=round(30 / 0.25)) \
        is None


def backlashes(step_A: float, play_step: bool) -> list[float]:
    t, q, current = sweep(step_A)
    result = identify_sweep(t, q, q, current, IdentifyOptions(backlash_play_step=play_step))
    return [*result.values["backlash_pos_deg"], *result.values["backlash_neg_deg"]]


def test_with_the_products_choice_each_backlash_ends_at_its_step() -> None:
    values = backlashes(-0.010, play_step=True)
    assert values
    assert all(abs(v - PLAY_DEG) <= 1.0 for v in values)


def test_without_the_choice_the_rules_end_stands() -> None:
    values = backlashes(-0.010, play_step=False)
    assert values
    assert all(v < PLAY_DEG - 5.0 for v in values)


def test_with_the_choice_a_current_without_a_step_gives_no_backlash() -> None:
    assert backlashes(0.0, play_step=True) == []


@pytest.mark.parametrize("sheet", sorted(p.name for p in SHEETS.glob("*.yaml")))
def test_only_planetwists_shipped_sheet_takes_the_play_step(sheet: str) -> None:
    device = load_device_model(SHEETS / sheet)
    taken = [bool(k.backlash_play_step) for k in device.knobs]
    assert taken == ([True, True] if sheet == "planetwist.yaml" else [False, False])
