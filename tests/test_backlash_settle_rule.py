"""The per-product backlash rule: the data sheet measures how far the current has come back when
the tip starts to move; calibration ends the backlash there when the current is still short of
its release level (docs/calibration.md)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml
from support.profiles import DEVICE

from tsmd.calibration.options import SETTLED_FRACTION, IdentifyOptions, for_product
from tsmd.calibration.release import recovered_end
from tsmd.calibration.run import device_options
from tsmd.calibration.signal import Conditioned
from tsmd.datasheet_release import backlash_settle_fraction
from tsmd.profile import ProfileError, device_model_to_mapping, load_device_model


def _sweep_after_reversal(tip_start_deg: float, current_settles_deg: float,
                          turning_current_A: float = 1.0, per_deg: int = 10
                          ) -> tuple[Conditioned, np.ndarray, np.ndarray]:
    """Knob 0 -> +90 -> -90 -> 0 deg at 10 deg/s. After the +90 deg reversal the current falls
    linearly from 1 A to its release level 0 A over ``current_settles_deg`` of knob travel; the
    tip holds for ``tip_start_deg`` and then comes back at the knob's slope. While the knob
    rests at +90 deg the current turns from ``turning_current_A`` to 1 A (the motor's friction
    turning)."""
    up = np.linspace(0.0, 90.0, 90 * per_deg + 1)
    dwell = np.full(20, 90.0)
    down = np.linspace(90.0, -90.0, 180 * per_deg + 1)[1:]
    back = np.linspace(-90.0, 0.0, 90 * per_deg + 1)[1:]
    pos = np.concatenate([up, dwell, down, back])
    t = np.arange(pos.size) * 0.1 / per_deg
    travel = 90.0 - down
    current = np.concatenate([np.ones(up.size), np.linspace(turning_current_A, 1.0, dwell.size),
                              np.clip(1.0 - travel / current_settles_deg, 0.0, 1.0),
                              np.zeros(back.size)])
    current[up.size - 1] = turning_current_A  # the turning point itself
    tip = np.concatenate([up, dwell, 90.0 - np.maximum(travel - tip_start_deg, 0.0),
                          np.full(back.size, 90.0 - (180.0 - tip_start_deg))])
    data = Conditioned(t, pos, pos, current, current, 10.0 * per_deg, 0.001, 0.0005, ())
    return data, t, tip


def test_the_share_of_the_current_swing_made_up_when_the_tip_moves_is_measured() -> None:
    # the tip counts as moving once it is 1 deg back: at 18.9 deg of travel (the 0.25 deg grid:
    # 19), 19/30 of the swing
    data, t, tip = _sweep_after_reversal(tip_start_deg=17.9, current_settles_deg=30.0)
    assert backlash_settle_fraction(data, t, tip) == pytest.approx(19.0 / 30.0, abs=0.005)


def test_a_current_settled_before_the_tip_moves_measures_as_one() -> None:
    data, t, tip = _sweep_after_reversal(tip_start_deg=25.0, current_settles_deg=20.0)
    assert backlash_settle_fraction(data, t, tip) == pytest.approx(1.0)


def test_tracker_noise_on_the_tip_does_not_make_the_share_early() -> None:
    # 0.2 deg of noise at 1 kHz: the raw tip's 1 deg threshold fired degrees early; the share
    # is read on the tip as the scoring truth reads it (low-passed)
    data, t, tip = _sweep_after_reversal(tip_start_deg=17.9, current_settles_deg=30.0,
                                         per_deg=100)
    noisy = tip + np.random.default_rng(3).normal(0.0, 0.2, tip.size)
    assert backlash_settle_fraction(data, t, noisy) == pytest.approx(19.0 / 30.0, abs=0.005)


def test_the_loaded_current_is_read_after_the_turning_point_as_calibration_reads_it() -> None:
    # a friction spike on the turning point's one sample must not widen the swing
    data, t, tip = _sweep_after_reversal(tip_start_deg=17.9, current_settles_deg=30.0,
                                         turning_current_A=1.5)
    assert backlash_settle_fraction(data, t, tip) == pytest.approx(19.0 / 30.0, abs=0.005)


def test_a_product_whose_current_is_short_of_its_level_uses_the_fraction_rule() -> None:
    opts = for_product(IdentifyOptions(), 0.95)
    assert (opts.backlash, opts.backlash_fraction) == ("fraction", 0.95)


@pytest.mark.parametrize("share", [None, SETTLED_FRACTION, 1.0])
def test_a_settled_or_unknown_product_keeps_the_papers_settle_rule(share: float | None) -> None:
    assert for_product(IdentifyOptions(), share) == IdentifyOptions()


def test_each_knob_gets_its_own_products_rule() -> None:
    device = load_device_model(DEVICE)
    knobs = (replace(device.knobs[0], backlash_settle_fraction=0.95),
             replace(device.knobs[1], backlash_settle_fraction=None))
    phi1, phi2 = device_options(None, replace(device, knobs=knobs))
    assert phi1.backlash == "fraction" and phi2.backlash == "settle"


def test_a_sheet_without_the_share_loads_and_keeps_the_settle_rule() -> None:
    device = load_device_model(DEVICE)
    assert all(k.backlash_settle_fraction is None for k in device.knobs) or all(
        k.backlash_settle_fraction is not None for k in device.knobs)
    stripped = device_model_to_mapping(device)
    for k in stripped["knobs"].values():
        for name in ("backlash_settle_fraction", "backlash_release_rule", "backlash_knee",
                     "reference_rule_backlash_gain",
                     "dead_zone_unit_u95_deg", "backlash_unit_u95_deg"):  # the sample's part
            k.pop(name, None)
    assert device_options(None, _load(stripped)) == (IdentifyOptions(), IdentifyOptions())


def test_an_implausible_share_is_refused_naming_it(tmp_path: Path) -> None:
    mapping = device_model_to_mapping(load_device_model(DEVICE))
    mapping["knobs"]["phi2"]["backlash_settle_fraction"] = 1.5
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(mapping))
    with pytest.raises(ProfileError, match="phi2.backlash_settle_fraction"):
        load_device_model(path)


def _load(mapping: dict[str, object]):  # type: ignore[no-untyped-def]
    from tsmd.profile import device_model_from_mapping

    return device_model_from_mapping(mapping, "test")


def test_the_fraction_is_of_the_swing_to_the_current_s_median_after_the_end() -> None:
    # direction-signed current after a reversal: from -1 A it rises linearly to its release
    # level 0 A over 20 deg and stays there; 95 % of the swing is made up at 19 deg
    grid = np.arange(0.0, 60.0, 0.25)
    current = np.clip(-1.0 + grid / 20.0, -1.0, 0.0)
    opts = replace(IdentifyOptions(), backlash="fraction", backlash_fraction=0.95)
    # a level line read off a short first flat run, 0.1 A low: the end must not follow it
    biased_level = np.array([0.0, -0.1])
    k = recovered_end(grid, current, 0, grid.size, biased_level, opts)
    assert grid[k] == pytest.approx(19.0, abs=0.3)


def _slow_release(noise_A: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Direction-signed current after a reversal that approaches its release level 0 A from
    -1 A ever more slowly, reaching it at 30 deg (95 % of the swing made up at 18.95 deg), with
    low-passed noise (correlated over about 1 deg, as the 20 Hz filter leaves it)."""
    grid = np.arange(0.0, 70.0, 0.25)
    rng = np.random.default_rng(seed)
    kernel = np.ones(4) / 2.0
    noise = np.convolve(rng.normal(0.0, noise_A, grid.size + 3), kernel, mode="valid")
    return grid, -np.clip(1.0 - grid / 30.0, 0.0, 1.0) ** 3 + noise


FRACTION_95 = replace(IdentifyOptions(), backlash="fraction", backlash_fraction=0.95)
TRUE_END_DEG = 30.0 * (1.0 - 0.05 ** (1.0 / 3.0))


def test_noise_on_a_slowly_settling_current_moves_the_end_by_less_than_0_45_deg() -> None:
    ends = []
    for seed in range(20):
        grid, current = _slow_release(noise_A=0.01, seed=seed)
        ends.append(grid[recovered_end(grid, current, 0, grid.size, np.array([0.0, 0.0]),
                                       FRACTION_95)])
    # (the first sample holding above the share: 0.55 deg on these draws)
    assert np.mean(np.abs(np.asarray(ends) - TRUE_END_DEG)) < 0.45


def test_a_noise_peak_after_the_shares_crossing_does_not_delay_the_end() -> None:
    # find_peaks marks a bump at 26 deg as the peak after the reversal (a release without one)
    grid, current = _slow_release(noise_A=0.0, seed=0)
    late_peak = int(np.searchsorted(grid, 26.0))
    k = recovered_end(grid, current, late_peak, grid.size, np.array([0.0, 0.0]), FRACTION_95)
    assert grid[k] == pytest.approx(TRUE_END_DEG, abs=0.5)
