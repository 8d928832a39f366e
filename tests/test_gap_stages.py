"""Gap diagnosis stages on arrays: input checks, split, replay, fits, statistics, breakdown."""

from __future__ import annotations

import numpy as np
import pytest
from support.gap import StandInPlant, make_recording

from tsmd.gap.candidates import RateDependence, catalogue, play
from tsmd.gap.data import make_split, parse_holdout, series_from_recording
from tsmd.gap.diagnose import is_significant
from tsmd.gap.errors import GapError
from tsmd.gap.fit import ParamSpec, fit_base
from tsmd.gap.model import Evaluator, View, build_views
from tsmd.gap.result import GapConfig
from tsmd.gap.simulate import eval_grid, fit_grid, lowpass, simulate, turning_points
from tsmd.gap.stats import bootstrap_ratio_ci, ljung_box, noise_variance, ptpe
from tsmd.gap.where import breakdown, label_knob, reversals
from tsmd.recording import Recording


def _rec(seed: int = 0, **plant: float) -> Recording:
    return make_recording(duration_s=120.0, rate_hz=20.0, seed=seed, **plant)


# --- bad inputs ---------------------------------------------------------------------------------

def test_missing_current_column_is_named() -> None:
    rec = _rec()
    del rec.columns["cur2"]
    with pytest.raises(GapError, match="missing column 'cur2'"):
        series_from_recording(rec, "r")


def test_recording_without_tip_is_refused() -> None:
    rec = _rec()
    rec.columns["tip1"][:] = np.nan
    with pytest.raises(GapError, match="no tip measurement"):
        series_from_recording(rec, "r")


def test_too_short_recording_is_refused() -> None:
    with pytest.raises(GapError, match="too short"):
        series_from_recording(_rec().slice(0, 50), "r")


def test_nan_in_a_used_column_names_column_and_row() -> None:
    rec = _rec()
    rec.columns["cur1"][17] = np.nan
    with pytest.raises(GapError, match=r"'cur1'.*row 18"):
        series_from_recording(rec, "r")


def test_non_increasing_time_is_refused() -> None:
    rec = _rec()
    rec.columns["t"][10] = rec.columns["t"][9]
    with pytest.raises(GapError, match="not strictly increasing"):
        series_from_recording(rec, "r")


def test_commanded_motion_is_used_when_position_is_missing() -> None:
    rec = _rec()
    rec.columns["pos1"][:] = np.nan
    s = series_from_recording(rec, "r")
    assert s.knob_source == "cmd"
    np.testing.assert_array_equal(s.knob_deg[:, 0], rec.columns["cmd1"])


def test_holdout_parses_fraction_or_names() -> None:
    assert parse_holdout("0.3") == 0.3
    assert parse_holdout("a.csv,b.csv") == ["a.csv", "b.csv"]
    with pytest.raises(GapError, match="0.05..0.6"):
        parse_holdout("0.9")


# --- split ----------------------------------------------------------------

def test_split_interleaves_held_out_blocks_disjoint_from_training() -> None:
    s = series_from_recording(_rec(), "r")
    split = make_split([s], 0.3)
    ho = split.held_out[0]
    assert 0.2 < ho.mean() < 0.45
    blocks = split.test_blocks()
    assert len(blocks) >= 3
    for _, mask in blocks:
        assert ho[mask].all()
    # held-out blocks are spread over the run, not one stretch
    starts = [np.flatnonzero(m)[0] for _, m in blocks]
    assert starts[0] < len(ho) / 2 < starts[-1]


def test_split_by_recording_name_holds_out_that_recording_whole() -> None:
    a = series_from_recording(_rec(), "a")
    b = series_from_recording(_rec(seed=2), "b")
    split = make_split([a, b], ["b"])
    assert not split.held_out[0].any() and split.held_out[1].all()


def test_split_of_too_little_data_is_refused() -> None:
    s = series_from_recording(_rec().slice(0, 120), "r")
    with pytest.raises(GapError, match="too short|held-out blocks"):
        make_split([s], 0.3, block_s=3.0)


# --- replay ----------------------------------------------------------------

def test_replay_steps_the_plant_once_per_row() -> None:
    t = np.arange(0, 10, 0.1)
    knob = np.column_stack([np.linspace(0, 60, len(t)), np.zeros(len(t))])
    tip, torque = simulate(StandInPlant(slack_deg=10, play_deg=0), t, knob)
    assert tip.shape == torque.shape == (len(t), 2)
    assert tip[-1, 0] == pytest.approx(1.3 * 50)


class _StiffPlant(StandInPlant):
    """Fails on a step longer than 0.05 s, as an implicit plant may on thinned replay rows."""

    def step(self, dt_s: float, knob_deg: np.ndarray) -> object:
        if dt_s > 0.05:
            raise FloatingPointError("step did not converge")
        return super().step(dt_s, knob_deg)


def test_a_step_the_plant_cannot_take_is_replayed_in_parts() -> None:
    t = np.concatenate([np.arange(0, 5, 0.02), 5.0 + np.arange(1, 6) * 0.2])
    knob = np.column_stack([np.linspace(0, 60, len(t)), np.zeros(len(t))])
    tip, _ = simulate(_StiffPlant(slack_deg=10, play_deg=0), t, knob)
    assert np.all(np.isfinite(tip))
    assert tip[-1, 0] == pytest.approx(1.3 * 50)


def test_a_plant_failing_even_in_parts_stops_with_one_line() -> None:
    t = np.arange(0, 10, 1.0)
    knob = np.column_stack([np.linspace(0, 60, len(t)), np.zeros(len(t))])
    with pytest.raises(GapError, match="simulator plant failed at t = 0.000 s"):
        simulate(_StiffPlant(slack_deg=10, play_deg=0), t, knob)


def test_eval_grid_keeps_every_held_out_row() -> None:
    ho = np.zeros(1000, dtype=bool)
    ho[300:420] = True
    rows = eval_grid(ho, 10)
    assert set(np.flatnonzero(ho)) <= set(rows.tolist())
    assert len(rows) < 250
    assert fit_grid(1000, 10)[-1] == 999


def test_turning_points_are_the_peaks_and_valleys_not_the_jitter() -> None:
    t = np.linspace(0, 20, 2001)
    x = 10 * np.sin(t) + np.random.default_rng(0).normal(0, 0.05, len(t))
    turns = turning_points(x, 0.5)
    np.testing.assert_allclose(t[turns], np.pi / 2 + np.pi * np.arange(6), atol=0.15)
    assert len(turning_points(np.random.default_rng(1).normal(0, 0.05, 500), 0.5)) == 0


def test_thinned_fit_grid_keeps_the_tops_of_fast_sweeps() -> None:
    x = np.abs((np.arange(1000) % 40) - 20.0)  # triangle, period 40 rows, peaks off the stride
    rows = fit_grid(1000, 15, np.column_stack([x, np.zeros(1000)]))
    assert x[rows].max() == 20.0 and x[rows].min() == 0.0
    peaks = np.flatnonzero(x == 20.0)[1:-1]
    assert set(peaks.tolist()) <= set(rows.tolist())


def test_rate_candidate_keeps_a_fast_sweeps_loop_wide_through_its_reversal() -> None:
    t = np.arange(0, 40, 0.01)
    fast = np.where(t < 20, 60 * (2 / np.pi) * np.arcsin(np.sin(2 * np.pi * t / 2.0)),
                    60 * (2 / np.pi) * np.arcsin(np.sin(2 * np.pi * t / 20.0)))
    s = series_from_recording(Recording({
        "t": t, "q1": fast, "q2": 0 * t, "cmd1": fast, "cmd2": 0 * t, "pos1": fast,
        "pos2": 0 * t, "cur1": 0 * t, "cur2": 0 * t, "tip1": fast, "tip2": 0 * t}, {}), "r")
    view = build_views([s], make_split([s], 0.3), [1], "fit")[0]
    out = RateDependence().knob(np.array([5.0]), view, view.knob_deg)[:, 0]
    fast_part, slow_part = (t > 2) & (t < 19), t > 22
    # the output turns short of the knob's peak by the play: wide loops when fast only
    assert fast[fast_part].max() - out[fast_part].max() == pytest.approx(5.0, abs=0.5)
    assert fast[slow_part].max() - out[slow_part].max() < 1.0


def test_lowpass_matches_first_order_step_response() -> None:
    t = np.linspace(0, 1, 1001)
    y = lowpass(t, np.ones(1001) * (t > 0), 0.1)
    assert y[np.searchsorted(t, 0.1)] == pytest.approx(1 - np.exp(-1), abs=2e-3)


# --- fit ----------------------------------------------------------------

def _evaluator(views: list[View], noise: np.ndarray) -> Evaluator:
    return Evaluator(lambda p: StandInPlant(**p), {"slack_deg": 10.0, "play_deg": 10.0},
                     noise, np.array([1.0, 1.0]))


def test_base_fit_recovers_the_dead_zone_from_training_rows() -> None:
    s = series_from_recording(_rec(slack_deg=18.0), "r")
    split = make_split([s], 0.3)
    views = build_views([s], split, [2], "fit")
    ev = _evaluator(views, np.array([0.09, 0.09, 2.5e-5, 2.5e-5]))
    params, _ = fit_base(ev, views, [ParamSpec("slack_deg", 5.0, 30.0)], max_evals=20)
    assert params["slack_deg"] == pytest.approx(18.0, abs=1.0)


def test_base_fit_never_sees_held_out_rows() -> None:
    rec = _rec(slack_deg=18.0)
    s = series_from_recording(rec, "r")
    split = make_split([s], 0.3)
    rec.columns["tip1"][split.held_out[0]] += 40.0  # corrupt only held-out rows
    s_bad = series_from_recording(rec, "r")
    fits = []
    for series in (s, s_bad):
        views = build_views([series], split, [2], "fit")
        ev = _evaluator(views, np.array([0.09, 0.09, 2.5e-5, 2.5e-5]))
        fits.append(fit_base(ev, views, [ParamSpec("slack_deg", 5.0, 30.0)], 15)[0])
    assert fits[0] == fits[1]


def test_every_candidate_transform_is_identity_at_neutral_parameters() -> None:
    s = series_from_recording(_rec(), "r")
    split = make_split([s], 0.3)
    views = build_views([s], split, [4], "fit")
    ev = _evaluator(views, np.ones(4))
    ev.predict(views, [])  # fills the base simulation the candidates read
    view = views[0]
    regs = np.random.default_rng(0).normal(size=(len(view.rows), 4))
    for cand in catalogue(np.array([0.1, 0.1])):
        theta = np.array(cand.neutral)
        np.testing.assert_allclose(cand.knob(theta, view, view.knob_deg), view.knob_deg,
                                   err_msg=cand.name)
        np.testing.assert_allclose(cand.current_filter(theta, view, regs), regs,
                                   err_msg=cand.name)


def test_play_operator_holds_output_until_input_turns_by_the_play() -> None:
    x = np.concatenate([np.linspace(0, 10, 11), np.linspace(9, 0, 10)])
    y = play(x, 2.0)
    assert y[10] == 8.0 and y[12] == 8.0 and y[14] == 8.0 and y[15] == 7.0


# --- statistics ----------------------------------------------------------------

def test_noise_variance_recovers_white_noise_on_a_smooth_signal() -> None:
    rng = np.random.default_rng(0)
    t = np.linspace(0, 100, 20000)
    y = 30 * np.sin(0.1 * t) + rng.normal(0, 0.5, t.size)
    assert np.sqrt(noise_variance(y)) == pytest.approx(0.5, rel=0.05)


def test_ljung_box_tells_white_from_correlated_residuals() -> None:
    rng = np.random.default_rng(1)
    white = rng.normal(size=3000)
    ar = lowpass(np.arange(3000.0), white, 5.0)
    assert ljung_box(white)[1] > 0.01
    assert ljung_box(ar)[1] < 1e-6


def test_bootstrap_interval_contains_the_point_and_excludes_zero_for_a_clear_gain() -> None:
    rng = np.random.default_rng(2)
    den = rng.uniform(90, 110, 20)
    num = 0.5 * den + rng.normal(0, 3, 20)
    point, lo, hi = bootstrap_ratio_ci(num, den, seed=0)
    assert lo < point < hi and lo > 0.4 and hi < 0.6


def test_significance_bound_tightens_with_the_number_of_candidates_tried() -> None:
    excess = np.full(16, 100.0)
    gain = 9.0 + 18.0 * np.linspace(-1.6, 1.6, 16)  # weak: clear for one candidate, not for six
    cfg = GapConfig()
    assert is_significant(gain, excess, 1, cfg)
    assert not is_significant(gain, excess, 6, cfg)
    assert not is_significant(np.full(16, 2.0), excess, 1, cfg)  # under min_share


def test_ptpe_is_highest_minus_lowest_error() -> None:
    assert ptpe(np.array([-1.0, 2.0, 0.5])) == 3.0


# --- where ----------------------------------------------------------------

def test_reversals_are_flagged_at_the_turning_points() -> None:
    t = np.linspace(0, 100, 5001)
    flags = reversals(60 * np.sin(2 * np.pi * t / 25), 1.0)
    np.testing.assert_allclose(t[flags], [6.25, 18.75, 31.25, 43.75, 56.25, 68.75, 81.25, 93.75],
                               atol=0.05)


def test_regimes_label_dead_zone_reversal_and_loaded_rows() -> None:
    t = np.arange(0, 100, 0.05)
    knob = 80 * np.sin(2 * np.pi * t / 50)
    tip, _ = simulate(StandInPlant(slack_deg=20, play_deg=10), t,
                      np.column_stack([knob, np.zeros_like(knob)]))
    vel = np.gradient(knob, t)
    lab = label_knob(t, knob, np.zeros_like(knob), vel, tip[:, 0], t, 100.0,
                     np.array([0, 5, 10, 100.0])).labels["regime"]
    assert lab[np.argmin(np.abs(t - 14.5))] == "after reversal"  # just after the top
    assert lab[np.argmin(np.abs(t - 6.0))] == "loaded"           # rising, tendon engaged
    assert lab[np.argmin(np.abs(t - 25.0))] == "dead zone"       # crossing zero


def test_breakdown_attributes_a_bias_to_the_bin_that_holds_it() -> None:
    n = 1000
    t = np.linspace(0, 100, n)
    knob = 80 * np.sin(2 * np.pi * t / 50)
    vel = np.gradient(knob, t)
    lab = label_knob(t, knob, np.zeros(n), vel, knob, t, 100.0, np.array([0, 5, 10, 100.0]))
    resid = np.where(vel > 0, 1.0, 0.0) + np.random.default_rng(0).normal(0, 0.05, n)
    shares, rows = breakdown([resid], [lab])
    assert shares["direction"] + shares["constant offset"] > 0.9
    assert shares["direction"] > max(
        v for k, v in shares.items() if k not in ("direction", "constant offset"))
    plus = next(r for r in rows if r.factor == "direction" and r.bin == "+")
    assert plus.share_gap > 0.95


def test_a_move_shifts_several_parameters_together_within_their_bounds() -> None:
    s = series_from_recording(_rec(slack_deg=18.0, play_deg=12.0), "r")
    split = make_split([s], 0.3)
    views = build_views([s], split, [2], "fit")
    ev = _evaluator(views, np.array([0.09, 0.09, 2.5e-5, 2.5e-5]))
    specs = [ParamSpec("slack_deg+play_deg", -6.0, 6.0), ParamSpec("slack_deg", 5.0, 30.0),
             ParamSpec("play_deg", 0.0, 20.0)]
    params, _ = fit_base(ev, views, specs, max_evals=30)
    assert params["slack_deg"] == pytest.approx(18.0, abs=1.0)
    assert params["play_deg"] == pytest.approx(12.0, abs=1.0)


def test_effect_size_measures_the_tip_gap_of_the_effect_alone() -> None:
    from tsmd.gap.selftest import effect_size

    coupling = effect_size("coupling", 20.0, 0, effects={"coupling": 0.5})
    stronger = effect_size("coupling", 20.0, 0, effects={"coupling": 1.0})
    nothing = effect_size("coupling", 20.0, 0, effects={})
    sensor = effect_size("sensor", 20.0, 0)
    assert nothing.tip_rmse_deg == 0.0 and nothing.cur_rmse_A == 0.0
    assert 0.0 < coupling.tip_rmse_deg < stronger.tip_rmse_deg
    # the current filter leaves the tip alone and moves only the current
    assert sensor.tip_rmse_deg == 0.0 and sensor.cur_rmse_A > 1e-3


def test_selftest_recording_is_the_noise_free_plant_output_plus_tracker_noise() -> None:
    from simrig.plant import load_plant
    from tsmd.gap.selftest import (
        BUILTIN_PLANT,
        drive_plant,
        make_real_recording,
        trajectory,
        unit_knobs,
    )

    rec = make_real_recording("none", 10.0, 50.0, seed=3)
    _t, q = trajectory(10.0, 50.0)
    tip, _cur = drive_plant(load_plant(BUILTIN_PLANT, {"knobs": unit_knobs(3, 0.15)}), q, 50.0)
    noise = rec.columns["tip1"] - tip[:, 0]
    assert 0.07 < float(np.std(noise)) < 0.13  # the tracker's 0.1 deg noise, nothing else
