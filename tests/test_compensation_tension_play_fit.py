"""Identification of the tension play from calibration current, and its profile section."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from support.profiles import assert_sheet_knob_field_round_trips, make_profile

from tsmd.calibration.load_ramp import fit_side, friction_current_A
from tsmd.calibration.release_path import release_through_amplitude
from tsmd.calibration.tension_play_fit import (
    SweepCurrent,
    fit_tension_play,
    median_of_three,
    smooth_over_grid,
)
from tsmd.calibration.unit_slope import unit_omega
from tsmd.compensation import CompensationError, build_compensator
from tsmd.compensation.loaded_shape import LoadedShape
from tsmd.compensation.release_ratio import release_slope_ratio
from tsmd.compensation.safety import KnobLimits
from tsmd.compensation.tension_play import release_line
from tsmd.compensation.tension_play_params import (
    BETA_RANGE,
    TensionPlayParams,
    tension_play_from_mapping,
    tension_play_to_mapping,
)
from tsmd.profile import (
    DeviceKnob,
    ProfileError,
    ReferencePoint,
    load_profile,
    profile_to_mapping,
    save_profile,
)

PERIOD_S = 0.004
D_POS, D_NEG, X0_POS, X0_NEG = 20.0, -22.0, 12.0, -13.0
DEVICE_KNOB = DeviceKnob(1.5, ReferencePoint(90.0, 100.0), ReferencePoint(-90.0, -100.0),
                         KnobLimits(-90.0, 90.0, 120.0, 2000.0))


def synthetic_sweep(other_deg: float = 0.0, amplitude_deg: float = 90.0, seed: int = 0,
                    offset_A: float = 0.004, backlash_deg: float = 25.0) -> SweepCurrent:
    """A +-A sine sweep whose current is friction (sign of the speed, plus a sensor offset) and
    a tension ramp from the zero-tension points, as a capstan drive shows on its loaded side."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 50.0, PERIOD_S)
    pos = -amplitude_deg * np.cos(2 * math.pi * 0.04 * t)
    v = np.gradient(pos)
    load = np.where((v > 0) & (pos > D_POS), 0.003 * (pos - X0_POS), 0.0)
    load += np.where((v < 0) & (pos < D_NEG), 0.003 * (pos - X0_NEG), 0.0)
    current = offset_A + 0.03 * np.sign(v) + load + rng.normal(0.0, 0.002, t.size)
    return SweepCurrent(other_deg, t, pos, pos, current, D_POS, D_NEG, backlash_deg,
                        backlash_deg)


def test_zero_tension_point_is_where_the_ramp_meets_the_friction_current() -> None:
    s = synthetic_sweep()
    zero = friction_current_A(s.pos_deg, s.current_A, D_POS, D_NEG, 1)
    side = fit_side(s.pos_deg, s.current_A, 1, D_POS, 25.0, zero)
    assert side.zero_load_deg == pytest.approx(X0_POS, abs=0.3)


def test_backlash_gain_is_the_calibration_backlash_over_the_loaded_run() -> None:
    s = synthetic_sweep()
    zero = friction_current_A(s.pos_deg, s.current_A, D_POS, D_NEG, -1)
    side = fit_side(s.pos_deg, s.current_A, -1, D_NEG, 25.0, zero)
    assert side.backlash_gain == pytest.approx(25.0 / (90.0 + X0_NEG), rel=0.01)


def test_sensor_offset_does_not_move_the_zero_tension_point() -> None:
    a = fit_tension_play([synthetic_sweep(g, offset_A=0.0) for g in (-90.0, 0.0, 90.0)],
                         DEVICE_KNOB)
    b = fit_tension_play([synthetic_sweep(g, offset_A=0.05) for g in (-90.0, 0.0, 90.0)],
                         DEVICE_KNOB)
    assert np.allclose(a.zero_load_pos_deg, b.zero_load_pos_deg, atol=0.05)


def test_fit_gives_every_parameter_on_the_sweeps_grid() -> None:
    grid = (-90.0, -30.0, 0.0, 30.0, 90.0)
    p = fit_tension_play([synthetic_sweep(g, seed=i) for i, g in enumerate(grid)], DEVICE_KNOB)
    assert p.other_knob_deg == grid
    assert np.allclose(p.zero_load_neg_deg, X0_NEG, atol=0.5)
    assert p.dead_zone_pos_deg == (D_POS,) * 5
    assert p.height_pos_deg == pytest.approx(100.0 - 1.5 * (90.0 - D_POS))


def test_edges_are_the_units_own_whatever_the_data_sheet_unit_showed() -> None:
    knob = dataclasses.replace(DEVICE_KNOB, dead_zone_offset_deg=0.5, release_omega=2.0,
                               reference_backlash_pos_deg=30.0, reference_backlash_neg_deg=30.0)
    p = fit_tension_play([synthetic_sweep(g) for g in (-90.0, 90.0)], knob)
    assert p == fit_tension_play([synthetic_sweep(g) for g in (-90.0, 90.0)], DEVICE_KNOB)
    assert p.dead_zone_pos_deg == (D_POS,) * 2


def test_plateau_heights_are_product_constants_with_the_data_sheet_units_edges() -> None:
    knob = dataclasses.replace(DEVICE_KNOB, reference_dead_zone_pos_deg=25.0,
                               reference_dead_zone_neg_deg=-25.0)
    p = fit_tension_play([synthetic_sweep(g) for g in (-90.0, 90.0)], knob)
    assert p.height_pos_deg == pytest.approx(100.0 - 1.5 * (90.0 - 25.0))
    assert p.height_neg_deg == pytest.approx(-100.0 + 1.5 * (90.0 - 25.0))


def test_unit_omega_is_the_products_release_slope_times_the_units_stretch_share() -> None:
    # omega_sheet / (1 - beta_sheet) is the product's; the unit keeps 1 - beta of it
    assert unit_omega(1.5, 0.3, 0.2) == pytest.approx(1.5 / 0.7 * 0.8)
    assert unit_omega(1.5, 0.3, 0.3) == pytest.approx(1.5)


def test_without_the_sheets_backlash_gain_omega_is_the_sheets() -> None:
    p = fit_tension_play([synthetic_sweep(g) for g in (-90.0, 0.0, 90.0)], DEVICE_KNOB)
    assert p.omega == 1.5
    assert unit_omega(1.5, None, 0.6) == 1.5


def test_fitted_omega_follows_the_units_backlash_gain_at_the_other_knobs_zero() -> None:
    # both sides read alike (the coupling's trend over the grid is not scatter): the reading
    # outweighs the sheet's own slope
    knob = dataclasses.replace(DEVICE_KNOB, reference_backlash_gain=0.2)
    grid = (-90.0, 0.0, 90.0)
    p = fit_tension_play([synthetic_sweep(g, backlash_deg=20.0 + 0.1 * g) for g in grid], knob)
    beta_0 = 0.5 * (p.backlash_gain_pos[1] + p.backlash_gain_neg[1])
    assert p.omega == pytest.approx(1.5 * (1.0 - beta_0) / 0.8, rel=0.005)
    assert beta_0 == pytest.approx(20.0 / (90.0 - 12.5), rel=0.03)


@pytest.mark.parametrize(("sign", "beta", "x0"), [(1, 0.35, 20.0), (-1, 0.3, -15.0),
                                                   (1, 0.3, 0.0)])
@pytest.mark.parametrize("ratio", [0.9, 0.93, 1.1])
def test_release_line_moved_keeps_the_backlash_end_at_the_amplitude(
        sign: int, beta: float, x0: float, ratio: float) -> None:
    omega, height, edge, amplitude = 1.3, 5.0 * sign, 24.0 * sign, 89.0 * sign
    b2, x02 = release_through_amplitude(beta, x0, amplitude, ratio)
    s1, c1 = release_line(omega, height, edge, beta, x0)
    s2, c2 = release_line(omega, height, edge, b2, x02)
    end = amplitude - beta * (amplitude - x0)
    assert s2 == pytest.approx(ratio * s1)
    assert s2 * end + c2 == pytest.approx(s1 * end + c1)


def test_release_line_is_never_shallower_than_the_loaded_line() -> None:
    beta, _ = release_through_amplitude(0.1, 5.0, 90.0, 0.8)
    assert BETA_RANGE[0] < beta <= BETA_RANGE[1]


@pytest.mark.parametrize("sign", [1, -1])
def test_moved_zero_load_point_stays_within_the_profiles_range(sign: int) -> None:
    # a small backlash gain and a shallower product: the anchored line would need x0 far out
    beta, x0 = release_through_amplitude(0.08, 10.0 * sign, 90.0 * sign, 0.8)
    assert abs(x0) <= 90.0
    assert BETA_RANGE[0] < beta <= BETA_RANGE[1]
    tension_play_from_mapping(tension_play_to_mapping(dataclasses.replace(
        fit_tension_play([synthetic_sweep(g) for g in (-90.0, 90.0)], DEVICE_KNOB),
        zero_load_pos_deg=(x0,) * 2, zero_load_neg_deg=(-abs(x0),) * 2,
        backlash_gain_pos=(beta,) * 2)))


def test_release_ratio_is_one_without_the_sheets_release_slope_or_backlash_gain() -> None:
    assert release_slope_ratio(DEVICE_KNOB) == 1.0
    assert release_slope_ratio(dataclasses.replace(DEVICE_KNOB, release_omega=2.0)) == 1.0
    assert release_through_amplitude(0.3, 10.0, 90.0, 1.0) == (0.3, 10.0)


def test_release_ratio_is_the_tracked_release_slope_over_the_backlash_end_locus() -> None:
    knob = dataclasses.replace(DEVICE_KNOB, release_omega=2.0, reference_backlash_gain=0.3)
    assert release_slope_ratio(knob) == pytest.approx(2.0 * 0.7 / 1.5)


def test_implausible_release_ratio_is_refused_in_one_line() -> None:
    knob = dataclasses.replace(DEVICE_KNOB, release_omega=5.0, reference_backlash_gain=0.3)
    with pytest.raises(ValueError, match="release/locus slope ratio") as err:
        release_slope_ratio(knob)
    assert "\n" not in str(err.value)


def test_fitted_release_line_has_the_products_ratio_and_the_units_backlash_end() -> None:
    grid = (-90.0, 0.0, 90.0)
    plain = dataclasses.replace(DEVICE_KNOB, reference_backlash_gain=0.2)
    knob = dataclasses.replace(plain, release_omega=1.5 / 0.8 * 0.9)
    p0 = fit_tension_play([synthetic_sweep(g) for g in grid], plain)
    p = fit_tension_play([synthetic_sweep(g) for g in grid], knob)
    assert p.omega == p0.omega  # the loaded line is the unit's either way
    for i in range(len(grid)):
        s0, c0 = release_line(p0.omega, p0.height_pos_deg, D_POS, p0.backlash_gain_pos[i],
                              p0.zero_load_pos_deg[i])
        s, c = release_line(p.omega, p.height_pos_deg, D_POS, p.backlash_gain_pos[i],
                            p.zero_load_pos_deg[i])
        amplitude = 90.0
        end = amplitude - p0.backlash_gain_pos[i] * (amplitude - p0.zero_load_pos_deg[i])
        assert s == pytest.approx(0.9 * s0)
        assert s * end + c == pytest.approx(s0 * end + c0, abs=0.05)


def test_unit_omega_stays_within_the_plausible_slopes() -> None:
    assert unit_omega(4.0, 0.8, 0.0) == 5.0
    assert unit_omega(0.3, 0.0, 0.8) == 0.2


def test_data_sheets_backlash_gain_round_trips_and_is_range_checked() -> None:
    assert_sheet_knob_field_round_trips("reference_backlash_gain", 0, 0.25, 1.5)


def test_sweep_too_small_for_the_dead_zone_is_refused_naming_it() -> None:
    with pytest.raises(ValueError, match=r"other knob at \+30 deg: too few samples"):
        fit_tension_play([synthetic_sweep(0.0), synthetic_sweep(30.0, amplitude_deg=26.0)],
                         DEVICE_KNOB)


def test_backlash_longer_than_the_loaded_run_is_refused() -> None:
    with pytest.raises(ValueError, match="does not fit a load ramp"):
        fit_tension_play([synthetic_sweep(g, backlash_deg=85.0) for g in (-90.0, 90.0)],
                         DEVICE_KNOB)


def test_one_sweeps_outlying_edge_is_removed_and_a_trend_kept() -> None:
    assert median_of_three([20.0, 20.2, 21.0, 20.1, 20.0]) == [20.0, 20.2, 20.2, 20.1, 20.0]
    assert median_of_three([43.0, 35.0, 28.0, 21.0]) == [43.0, 35.0, 28.0, 21.0]


def test_an_edge_confidently_off_its_neighbours_median_is_kept() -> None:
    # a dead zone wider at both ends of the other knob's range (a V): the vertex is the
    # catheter's when its deviation exceeds the calibration's uncertainties
    assert median_of_three([25.1, 19.9, 25.9], [0.9, 0.7, 0.9]) == [25.1, 19.9, 25.9]


def test_an_edge_off_its_neighbours_median_within_the_uncertainty_is_smoothed() -> None:
    assert median_of_three([25.1, 24.3, 25.9], [0.9, 0.7, 0.9]) == [25.1, 25.1, 25.9]


def test_the_fit_keeps_the_vertex_of_a_v_shaped_edge_given_its_uncertainty() -> None:
    def sweeps(u95: float) -> list[SweepCurrent]:
        out = []
        for g in (-90.0, 0.0, 90.0):
            s = synthetic_sweep(g)
            d = D_POS + (5.0 if g else 0.0)
            out.append(dataclasses.replace(s, dead_zone_pos_deg=d, dead_zone_u95_deg=(u95, u95)))
        return out

    assert fit_tension_play(sweeps(0.8), DEVICE_KNOB).dead_zone_pos_deg[1] == D_POS
    assert fit_tension_play(sweeps(math.inf), DEVICE_KNOB).dead_zone_pos_deg[1] == D_POS + 5.0


def test_a_backlash_larger_at_both_ends_of_three_grid_points_leaves_the_middles_omega_alone(
        ) -> None:
    device = dataclasses.replace(DEVICE_KNOB, reference_backlash_gain=0.3)
    v_shaped = fit_tension_play([synthetic_sweep(g, backlash_deg=40.0 if g else 20.0)
                                 for g in (-90.0, 0.0, 90.0)], device)
    flat = fit_tension_play([synthetic_sweep(g, backlash_deg=20.0)
                             for g in (-90.0, 0.0, 90.0)], device)
    # (the ends' sides differ a little more, which weighs the reading a little less)
    assert v_shaped.omega == pytest.approx(flat.omega, rel=0.003)


def test_seven_grid_points_are_smoothed_by_a_parabola() -> None:
    grid = [-90.0, -60.0, -30.0, 0.0, 30.0, 60.0, 90.0]
    noisy = [0.3 + 1e-5 * g * g + (0.01 if i == 3 else 0.0) for i, g in enumerate(grid)]
    smooth = smooth_over_grid(grid, noisy)
    assert abs(smooth[3] - noisy[3]) > 0.005
    assert smooth_over_grid(grid, [0.3 + 1e-5 * g * g for g in grid]) == pytest.approx(
        [0.3 + 1e-5 * g * g for g in grid])


def test_one_sweep_is_not_a_grid() -> None:
    with pytest.raises(ValueError, match=">= 2 other-knob angles"):
        fit_tension_play([synthetic_sweep()], DEVICE_KNOB)


# ----------------------------------------------------------------------------------------------
# Profile section


def profile_with_tension_play():  # type: ignore[no-untyped-def]
    p = fit_tension_play([synthetic_sweep(g) for g in (-90.0, 0.0, 90.0)], DEVICE_KNOB)
    base = make_profile()
    return dataclasses.replace(base, knobs=tuple(dataclasses.replace(k, tension_play=p)
                                                 for k in base.knobs))


def test_tension_play_section_round_trips_through_a_profile_file(tmp_path: Path) -> None:
    profile = profile_with_tension_play()
    save_profile(profile, tmp_path / "p.yaml")
    assert load_profile(tmp_path / "p.yaml") == profile


def test_bad_tension_play_value_is_one_line_error_naming_the_key(tmp_path: Path) -> None:
    data = profile_to_mapping(profile_with_tension_play())
    data["knobs"]["phi2"]["tension_play"]["backlash_gain_pos"][1] = 1.5
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    with pytest.raises(ProfileError, match=r"knobs\.phi2\.tension_play.*backlash_gain_pos\[1\]"):
        load_profile(path)


def test_mapping_refuses_unknown_and_missing_keys() -> None:
    m = tension_play_to_mapping(profile_with_tension_play().knobs[0].tension_play)
    with pytest.raises(ValueError, match="colour: unknown key"):
        tension_play_from_mapping({**m, "colour": 1.0})
    m.pop("zero_load_neg_deg")
    with pytest.raises(ValueError, match="zero_load_neg_deg: missing key"):
        tension_play_from_mapping(m)


def test_method_ours_on_a_profile_without_the_section_asks_for_recalibration() -> None:
    profile = make_profile()
    old = dataclasses.replace(profile, knobs=tuple(dataclasses.replace(k, tension_play=None)
                                                    for k in profile.knobs))
    with pytest.raises(CompensationError, match="recalibrate") as exc:
        build_compensator(old, "ours", PERIOD_S)
    assert "\n" not in str(exc.value)


def test_former_method_name_tension_is_refused_naming_ours() -> None:
    with pytest.raises(CompensationError, match="'tension' is now called 'ours'"):
        build_compensator(profile_with_tension_play(), "tension", PERIOD_S)


def test_method_ours_builds_from_a_profile_with_the_section() -> None:
    comp = build_compensator(profile_with_tension_play(), "ours", PERIOD_S)
    comp.reset(np.zeros(2))
    assert np.all(np.isfinite(comp.command(np.array([10.0, -10.0]), PERIOD_S)))


def test_a_sweeps_lag_already_estimated_is_used_as_it_is() -> None:
    from dataclasses import replace

    sweeps = [synthetic_sweep(g) for g in (-90.0, 0.0, 90.0)]
    p = fit_tension_play([replace(s, lag_s=0.3) for s in sweeps], DEVICE_KNOB)
    assert p.lag_s == 0.3


def test_a_sheets_template_puts_the_reference_point_on_the_bent_line() -> None:
    shape = LoadedShape((0.0, 10.0, 65.0), (0.0, 13.0, 70.0))
    knob = dataclasses.replace(DEVICE_KNOB, reference_dead_zone_pos_deg=25.0,
                               reference_dead_zone_neg_deg=-25.0, loaded_shape_pos=shape,
                               loaded_shape_neg=shape)
    p = fit_tension_play([synthetic_sweep(g) for g in (-90.0, 90.0)], knob)
    assert p.shape_pos == shape and p.shape_neg == shape
    assert p.height_pos_deg == pytest.approx(100.0 - 1.5 * 70.0)
    assert p.height_neg_deg == pytest.approx(-100.0 + 1.5 * 70.0)


def test_a_straight_template_fits_exactly_as_no_template() -> None:
    straight = LoadedShape((0.0, 65.0), (0.0, 65.0))
    knob = dataclasses.replace(DEVICE_KNOB, reference_dead_zone_pos_deg=25.0,
                               reference_dead_zone_neg_deg=-25.0)
    sweeps = [synthetic_sweep(g) for g in (-90.0, 90.0)]
    assert fit_tension_play(sweeps, dataclasses.replace(
        knob, loaded_shape_pos=straight, loaded_shape_neg=straight)) == fit_tension_play(
        sweeps, knob)


def _with_settle_backlash(sweeps: list[SweepCurrent], settle_deg: float) -> list[SweepCurrent]:
    return [dataclasses.replace(s, settle_backlash_deg=(settle_deg, settle_deg)) for s in sweeps]


def _rule_and_settle_fits() -> tuple[TensionPlayParams, TensionPlayParams]:
    """The play fitted where the profile's rule reads B 15 deg and the settle rule 25, and
    where both read 25."""
    grid = (-90.0, 0.0, 90.0)
    knob = dataclasses.replace(DEVICE_KNOB, reference_backlash_gain=0.2)
    rule = fit_tension_play(_with_settle_backlash(
        [synthetic_sweep(g, backlash_deg=15.0) for g in grid], 25.0), knob)
    settle = fit_tension_play([synthetic_sweep(g, backlash_deg=25.0) for g in grid], knob)
    return rule, settle


def test_the_play_is_fitted_on_the_profiles_backlash_not_the_settle_rules() -> None:
    rule, settle = _rule_and_settle_fits()
    assert rule.backlash_gain_pos[1] == pytest.approx(15.0 / (90.0 - X0_POS), rel=0.02)
    assert rule.backlash_gain_pos[1] < settle.backlash_gain_pos[1]


def test_a_settle_rule_sheet_gain_scales_omega_by_the_units_settle_rule_gain() -> None:
    rule, settle = _rule_and_settle_fits()
    assert rule.omega == pytest.approx(settle.omega)


def test_a_product_rule_gain_outweighs_a_settle_rule_whose_sides_disagree() -> None:
    grid = (-90.0, 0.0, 90.0)
    knob = dataclasses.replace(DEVICE_KNOB, reference_backlash_gain=0.2,
                               reference_rule_backlash_gain=0.2)
    sweeps = [dataclasses.replace(synthetic_sweep(g, backlash_deg=15.0),
                                  settle_backlash_deg=(15.0, 30.0)) for g in grid]
    p = fit_tension_play(sweeps, knob)
    rule_only = fit_tension_play(sweeps, dataclasses.replace(knob, reference_backlash_gain=None))
    settle_only = fit_tension_play(sweeps, dataclasses.replace(
        knob, reference_rule_backlash_gain=None))
    assert abs(p.omega - rule_only.omega) < 0.1 * abs(p.omega - settle_only.omega)


def test_a_non_finite_settle_backlash_leaves_omega_to_the_plays_gain() -> None:
    grid = (-90.0, 0.0, 90.0)
    knob = dataclasses.replace(DEVICE_KNOB, reference_backlash_gain=0.2)
    sweeps = [synthetic_sweep(g, backlash_deg=15.0) for g in grid]
    p = fit_tension_play(_with_settle_backlash(sweeps, math.nan), knob)
    assert p == fit_tension_play(sweeps, knob)
    assert math.isfinite(p.omega)
