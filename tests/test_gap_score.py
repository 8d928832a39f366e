"""Self-test scoring: an injected effect below the data's noise is expected to read none."""

from __future__ import annotations

from tsmd.gap.detectable import Footprint, condition_footprint, footprint
from tsmd.gap.presets import PRESETS
from tsmd.gap.score import SelftestCase, SelftestResult, selftest_markdown


def _case(case: str, expected: str | None, top: str | None,
          detectable: bool | None) -> SelftestCase:
    return SelftestCase(case, 240.0, 1, expected, "v", top, None, 1.0, None, 0.01, None, 1.0,
                        detectable=detectable)


def test_a_sheath_bend_on_the_helix_plant_leaves_less_than_the_noise_halved_tendons_more() -> None:
    bend = footprint(PRESETS["helixbelt"], "curvature", 1, 60.0, 50.0)
    tendons = footprint(PRESETS["helixbelt"], "compliance", 1, 60.0, 50.0)
    assert not bend.detectable(0.1, 0.004)
    assert tendons.detectable(0.1, 0.004)


def test_a_current_lag_is_detectable_on_the_current_alone() -> None:
    lag = footprint(PRESETS["helixbelt"], "sensor", 1, 60.0, 50.0)
    assert lag.tip_deg == 0.0
    assert lag.detectable(0.1, 0.004)
    assert not Footprint(0.0, 0.003).detectable(0.1, 0.004)


def test_an_effect_below_detection_read_none_is_a_miss_strictly_and_right_as_detectable() -> None:
    result = SelftestResult([_case("curvature", "curvature", None, False),
                             _case("coupling", "coupling", "coupling", True),
                             _case("none", None, None, None)])
    s = result.summary()
    assert s["top1_accuracy"] == 0.5
    assert s["top1_accuracy_detectable"] == 1.0
    assert (s["n_below_detection"], s["below_detection_read_none"]) == (1, 1)
    assert result.cases[0].correct_detectable and not result.cases[0].correct
    assert "below detection read none (expected) | 1/1" in selftest_markdown(result)


def test_an_effect_below_detection_that_is_named_is_right_strictly_only() -> None:
    lucky = _case("curvature", "curvature", "curvature", False)
    assert lucky.correct and not lucky.correct_detectable
    assert SelftestResult([lucky]).summary()["below_detection_read_none"] == 0


def test_an_effect_read_within_the_units_spread_is_counted_apart_and_stays_a_miss() -> None:
    inside = _case("coupling", "coupling", None, True)
    inside.within_spread = "coupling"
    null = _case("none", None, None, None)
    null.within_spread = "coupling"
    result = SelftestResult([inside, null, _case("rate", "rate", "rate", True)])
    s = result.summary()
    assert s["top1_accuracy"] == 0.5 and not inside.correct
    assert (s["within_spread_own_effect"], s["within_spread_null"]) == (1, 1)
    assert s["false_alarms"] == 0
    assert "units' spread' (not counted above) | 1/2" in selftest_markdown(result)


def test_another_effect_read_within_the_spread_is_no_reading_of_the_one_put_in() -> None:
    other = _case("rate", "rate", None, True)
    other.within_spread = "coupling"
    assert not other.spread_reading


def test_a_rate_case_is_sized_by_its_speed_contrast_not_by_how_far_it_moves_the_tip() -> None:
    # stickslip's fast relaxation branch x5 moves the tip 1.1 deg over the motion, but its
    # loops at 20 and 80 deg/s by less than one sample's noise; lumped's viscous sheath more
    branch = condition_footprint(PRESETS["stickslip"], "rate", 1, 50.0)
    viscous = condition_footprint(PRESETS["lumped"], "rate", 1, 50.0)
    assert footprint(PRESETS["stickslip"], "rate", 1, 60.0, 50.0).detectable(0.1, 0.004)
    assert not branch.detectable(0.1, 0.004)
    assert viscous.detectable(0.1, 0.004)


def test_a_creep_case_is_sized_by_its_drift_at_a_held_knob() -> None:
    # stickslip's slow relaxation branch x1.5 moves the tip 0.38 deg over the motion, but the
    # currents over a held dwell by 3.3 mA; the lumped plant's creep by more than 4 mA
    branch = condition_footprint(PRESETS["stickslip"], "creep", 1, 50.0)
    creep = condition_footprint(PRESETS["lumped"], "creep", 1, 50.0)
    assert footprint(PRESETS["stickslip"], "creep", 1, 60.0, 50.0).detectable(0.1, 0.004)
    assert not branch.detectable(0.1, 0.004)
    assert creep.detectable(0.1, 0.004)
