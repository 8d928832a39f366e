"""The rule "recovery" (a self-locking handle): B where the current's recovery from its overshoot
ends, plus the sheet's lag; where no half-cycle shows it, the sheet's backlash scaled by the
unit's swing, flagged, with its own half-width, no offset, no re-sweep (docs/calibration.md,
session 16)."""

from __future__ import annotations

import dataclasses
from functools import cache
from typing import Any

import numpy as np
import pytest
from support.profiles import DEVICE as DEVICE_PATH

from tsmd.calibration.assemble import GridPoint, QualityLimits, QualityReport, _check_uncertainty
from tsmd.calibration.estimate import point_estimates
from tsmd.calibration.identify import analyse_half_cycle, split_half_cycles
from tsmd.calibration.options import BacklashReference, IdentifyOptions, for_product
from tsmd.calibration.reading_offset import corrected
from tsmd.calibration.recovery import (
    UNSEEN_U95_SHARE,
    bend_gain,
    expected_backlash_deg,
    recovery_end,
    with_unseen,
)
from tsmd.calibration.resweep import uncertain_points
from tsmd.calibration.signal import Conditioned
from tsmd.calibration.sweep_result import HalfCycle, SweepResult
from tsmd.datasheet_rule import usable
from tsmd.profile import (
    ProfileError,
    device_model_from_mapping,
    device_model_to_mapping,
    load_device_model,
)
from tsmd.profile.reading_offset import OffsetGrid, ReadingOffset

NOISE_A = 0.002
CORNER_DEG = 10.0


def _recovering(overshoot_A: float, seed: int = 0) -> Conditioned:
    """Knob 60 -> 90 -> -90 deg, 10 samples per degree: after the reversal the current turns
    within about 1 deg (the collar), overshoots its release level by ``overshoot_A`` and
    recovers in a straight line that ends ``CORNER_DEG`` after the reversal; it loads again
    120 deg on. White noise of ``NOISE_A``."""
    up = np.linspace(60.0, 90.0, 301)
    down = np.linspace(90.0, -90.0, 1801)[1:]
    pos = np.concatenate([up, down])
    travel = 90.0 - down
    y = (0.1 - 1.1 * np.exp(-travel / 0.3)
         + overshoot_A / CORNER_DEG * np.maximum(CORNER_DEG - travel, 0.0)
         + 0.02 * np.maximum(travel - 120.0, 0.0))
    current = np.concatenate([np.linspace(0.9, 1.0, up.size), -y])
    current = current + np.random.default_rng(seed).normal(0.0, NOISE_A, current.size)
    t = np.arange(pos.size) * 1e-2
    return Conditioned(t, pos, pos, current, current, 100.0, NOISE_A, NOISE_A, ())


def _grid_current(data: Conditioned) -> tuple[np.ndarray, np.ndarray]:
    down = slice(300, None)
    grid = 90.0 - data.pos_deg[down]
    return grid, -data.current_filtered_A[down]


def _half(data: Conditioned, opts: IdentifyOptions) -> HalfCycle:
    halves = [analyse_half_cycle(data, d, a, b, r, opts)
              for d, a, b, r in split_half_cycles(data.cmd_deg, 10.0) if r]
    assert len(halves) == 1
    return halves[0]


RECOVERY = IdentifyOptions(backlash="recovery")


def test_the_recovery_ends_where_the_overshoot_has_gone() -> None:
    grid, y = _grid_current(_recovering(0.02))
    found = recovery_end(grid[::2] - grid[0], y[::2], NOISE_A)  # a 0.2 deg grid
    assert found is not None
    assert found.end * 0.2 == pytest.approx(CORNER_DEG, abs=0.6)
    assert found.visibility > RECOVERY.min_backlash_visibility


def test_a_current_without_an_overshoot_does_not_show_the_recovery() -> None:
    grid, y = _grid_current(_recovering(0.0))
    found = recovery_end(grid[::2] - grid[0], y[::2], NOISE_A)
    assert found is None or found.visibility < RECOVERY.min_backlash_visibility


def test_the_rule_ends_the_backlash_the_sheets_lag_after_the_recovery() -> None:
    plain = _half(_recovering(0.02), RECOVERY)
    lagged = _half(_recovering(0.02), dataclasses.replace(RECOVERY,
                                                          backlash_recovery_lag_deg=-3.0))
    assert plain.backlash_deg == pytest.approx(CORNER_DEG, abs=0.6)
    assert lagged.backlash_deg - plain.backlash_deg == pytest.approx(-3.0, abs=0.26)
    assert plain.backlash_visibility > RECOVERY.min_backlash_visibility


def test_a_product_naming_the_recovery_rule_gets_it_with_its_lag_and_reference() -> None:
    ref = BacklashReference(9.0, 8.5, 0.11)
    opts = for_product(IdentifyOptions(), 1.0, None, -1.5, 1.05, "recovery", 1.03, -3.3, ref)
    assert (opts.backlash, opts.backlash_recovery_lag_deg) == ("recovery", -3.3)
    assert opts.unseen_backlash == ref


def _swinging(swing_A: float, visibility: float) -> HalfCycle:
    return HalfCycle(-1, 0, 10, True, backlash_deg=2.0, release_swing_A=swing_A,
                     backlash_visibility=visibility)


def _sweep(*halves: HalfCycle, **values: tuple[float, ...]) -> SweepResult:
    return SweepResult(None, halves, dict(values))  # type: ignore[arg-type]


REFERENCE = BacklashReference(9.0, 8.5, 0.11, bend_gain=1.2)
WITH_REFERENCE = dataclasses.replace(RECOVERY, unseen_backlash=REFERENCE)


def test_an_unseen_backlash_is_the_sheets_scaled_by_the_units_own_swing() -> None:
    out = with_unseen(_sweep(_swinging(0.1, 3.0), _swinging(0.12, 5.0)), WITH_REFERENCE, 0.0)
    values = out.values["backlash_pos_deg"]
    assert values == tuple(pytest.approx(expected_backlash_deg(9.0, s, 0.11))
                           for s in (0.1, 0.12))
    assert out.unseen == {"backlash_pos_deg": pytest.approx(UNSEEN_U95_SHARE * max(values))}


def test_an_unseen_backlash_grows_by_the_sheets_bend_gain_with_the_other_knobs_bend() -> None:
    sweep = _sweep(_swinging(0.1, 3.0))
    at = {o: with_unseen(sweep, WITH_REFERENCE, o).values["backlash_pos_deg"][0]
          for o in (0.0, 45.0, -90.0)}
    assert at[-90.0] / at[0.0] == pytest.approx(1.2)
    assert at[45.0] / at[0.0] == pytest.approx(1.1)


def test_a_backlash_one_half_cycle_shows_is_not_replaced() -> None:
    sweep = _sweep(_swinging(0.1, 3.0), _swinging(0.12, 50.0), backlash_pos_deg=(2.0,))
    assert with_unseen(sweep, WITH_REFERENCE, 0.0) is sweep


def test_without_a_sheet_reference_nothing_replaces_an_unseen_backlash() -> None:
    sweep = _sweep(_swinging(0.1, 3.0))
    assert with_unseen(sweep, RECOVERY, 0.0) is sweep


def test_the_bend_gain_is_the_tips_backlash_over_the_swing_law_at_90_over_at_0() -> None:
    law = {s: expected_backlash_deg(9.0, s, 0.11) for s in (0.11, 0.13)}
    points = [(0.0, law[0.11], 0.11), (-90.0, 1.3 * law[0.13], 0.13), (90.0, 1.3 * law[0.13], 0.13)]
    assert bend_gain(points, 9.0, 0.11) == pytest.approx(1.3)


def test_no_reading_offset_applies_to_an_unseen_backlash_and_its_width_reaches_the_gate() -> None:
    offset = ReadingOffset((-90.0, 0.0, 90.0), (
        ("backlash_pos_deg", OffsetGrid((-2.0, -2.0, -2.0), (0.5, 0.5, 0.5), (4, 4, 4))),
        ("backlash_neg_deg", OffsetGrid((-2.0, -2.0, -2.0), (0.5, 0.5, 0.5), (4, 4, 4)))))
    result = SweepResult(None, (), {"backlash_pos_deg": (9.0, 9.2),  # type: ignore[arg-type]
                                    "backlash_neg_deg": (8.0, 8.4)},
                         unseen={"backlash_pos_deg": 3.6})
    out = corrected(result, offset, 0.0)
    assert out.values["backlash_pos_deg"] == (9.0, 9.2)
    assert out.values["backlash_neg_deg"] == pytest.approx((10.0, 10.4))
    assert out.offset_u95_deg == {"backlash_pos_deg": 3.6, "backlash_neg_deg": 0.5}


def test_an_unseen_backlash_is_warned_and_flagged_in_the_quality_figures_not_refused() -> None:
    values = {"dead_zone_pos_deg": (30.0, 30.1), "dead_zone_neg_deg": (-30.0, -30.1),
              "backlash_pos_deg": (9.0, 9.1), "backlash_neg_deg": (8.0, 8.1)}
    wide = SweepResult(None, (), values, unseen={"backlash_pos_deg": 4.0})  # type: ignore[arg-type]
    point = GridPoint(0, 0.0, corrected(wide, None, 0.0))
    report = QualityReport()
    _check_uncertainty(point, point_estimates([point.result])[0], 1.46, QualityLimits(), report)
    assert not report.problems  # 1.46 x 4 deg is beyond the 5 deg a reading is refused at
    assert any("backlash_pos_deg cannot be seen in the current" in w for w in report.warnings)
    assert report.figures["phi1_backlash_pos_unseen_at_+0_u95_deg"] == pytest.approx(4.0, abs=0.1)


def test_an_unseen_backlash_is_not_swept_again() -> None:
    values = {"dead_zone_pos_deg": (30.0, 30.1), "dead_zone_neg_deg": (-30.0, -30.1),
              "backlash_pos_deg": (9.0, 9.1), "backlash_neg_deg": (8.0, 8.1)}
    unseen = SweepResult(None, (), values, unseen={"backlash_pos_deg": 3.6})  # type: ignore[arg-type]
    point = GridPoint(0, 0.0, corrected(unseen, None, 0.0))
    assert uncertain_points([point], (1.46, 1.46)) == []
    seen_wide = GridPoint(0, 0.0, dataclasses.replace(point.result, unseen={}))
    assert [u.names for u in uncertain_points([seen_wide], (1.46, 1.46))] == [
        ("backlash_pos_deg",)]


@cache
def _sheet() -> dict[str, Any]:
    return device_model_to_mapping(load_device_model(DEVICE_PATH))


def test_a_sheet_naming_the_recovery_rule_needs_its_lag() -> None:
    raw = _sheet()
    knobs = dict(raw["knobs"])
    knobs["phi1"] = {**knobs["phi1"], "backlash_release_rule": "recovery"}
    with pytest.raises(ProfileError, match="'recovery' needs backlash_recovery_lag_deg"):
        device_model_from_mapping({**raw, "knobs": knobs})


def test_the_recovery_rule_and_its_lag_round_trip_through_the_sheet() -> None:
    raw = _sheet()
    knobs = dict(raw["knobs"])
    knobs["phi1"] = {**knobs["phi1"], "backlash_release_rule": "recovery",
                     "backlash_recovery_lag_deg": -3.3}
    device = device_model_from_mapping({**raw, "knobs": knobs})
    again = device_model_from_mapping(device_model_to_mapping(device))
    assert again.knobs[0].backlash_release_rule == "recovery"
    assert again.knobs[0].backlash_recovery_lag_deg == -3.3


def test_tsmd_datasheet_offers_the_recovery_rule_only_to_a_knob_with_its_lag() -> None:
    knob = load_device_model(DEVICE_PATH).knobs[0]
    assert not usable(knob, "recovery")
    assert usable(dataclasses.replace(knob, backlash_recovery_lag_deg=-3.3), "recovery")
