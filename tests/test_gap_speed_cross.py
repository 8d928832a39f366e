"""The base fit on a segment-subsampled copy of long recordings, and the lumped plant as either
side of the cross-plant self-test."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from support.gap import StandInPlant, make_recording

from simrig.family import family_member
from tsmd.gap.crosstest import make_session
from tsmd.gap.data import GapSeries, Split, fit_windows, make_split, series_from_recording
from tsmd.gap.fit import ParamSpec, fit_base
from tsmd.gap.model import Evaluator, build_views
from tsmd.gap.presets import PRESETS, parse_plant_spec
from tsmd.gap.selftest import EFFECTS, drive_plant, trajectory


def _long_series(duration_s: float = 600.0) -> tuple[GapSeries, Split]:
    rec = make_recording(duration_s=duration_s, rate_hz=20.0)
    s = series_from_recording(rec, "long")
    return s, make_split([s], 0.3)


def test_long_recordings_are_fitted_on_windows_of_the_given_length() -> None:
    s, split = _long_series()
    wins, _ = fit_windows([s], split, window_s=40.0, n_windows=4)
    assert len(wins) == 4
    for w in wins:
        assert w.duration_s <= 40.0
        assert s.t_s[0] <= w.t_s[0] and w.t_s[-1] <= s.t_s[-1]
    starts = [w.t_s[0] for w in wins]
    assert starts[-1] - starts[0] > 0.5 * s.duration_s  # spread over the recording


def test_window_rows_before_both_knobs_reverse_are_not_fitted() -> None:
    s, split = _long_series()
    wins, wsplit = fit_windows([s], split, window_s=40.0, n_windows=4)
    for w, held in zip(wins, wsplit.held_out, strict=True):
        assert held[0]  # the reset plant's state is unknown at the window's start
        rows = np.searchsorted(s.t_s, w.t_s)
        trained = ~held
        assert trained.any()
        assert not np.any(trained & split.held_out[0][rows])  # held-out rows stay held out


def test_base_fit_on_windows_recovers_the_dead_zone_of_the_whole_recording() -> None:
    rec = make_recording(duration_s=600.0, rate_hz=20.0, slack_deg=18.0)
    s = series_from_recording(rec, "long")
    split = make_split([s], 0.3)
    wins, wsplit = fit_windows([s], split, window_s=40.0, n_windows=4)
    views = build_views(wins, wsplit, [2] * len(wins), "fit")
    ev = Evaluator(lambda p: StandInPlant(**p), {"slack_deg": 10.0, "play_deg": 10.0},
                   np.array([0.09, 0.09, 2.5e-5, 2.5e-5]), np.array([1.0, 1.0]))
    params, _ = fit_base(ev, views, [ParamSpec("slack_deg", 5.0, 30.0)], max_evals=20)
    assert params["slack_deg"] == pytest.approx(18.0, abs=1.0)
    assert sum(len(v.rows) for v in views) < 0.3 * len(s) / 2  # a fraction of the rows


def test_short_recordings_are_fitted_whole() -> None:
    s, split = _long_series(120.0)
    wins, wsplit = fit_windows([s], split, window_s=60.0, n_windows=6)
    assert wins == [s] and wsplit is split


def test_lumped_preset_builds_the_family_unit_with_its_own_effect_keywords() -> None:
    lumped = parse_plant_spec("lumped")
    assert lumped is PRESETS["lumped"]
    for case in ("coupling", "rate", "compliance", "curvature", "creep"):
        assert lumped.case_effects(case)  # every plant effect has the plant's own keyword
    assert lumped.case_effects("sensor") == {} and lumped.case_effects("none") == {}
    plant = lumped.build_unit(101, 0.1, **lumped.case_effects("compliance"))
    nominal = lumped.build_unit(0, 0.1)
    assert type(plant).__name__ == type(nominal).__name__
    assert family_member("lumped", 101).params["knobs"] != family_member("lumped", 0).params[
        "knobs"]


def test_capstan_preset_keeps_the_selftest_effects() -> None:
    capstan = PRESETS["capstan"]
    for case, (effects, _, _) in EFFECTS.items():
        assert capstan.case_effects(case) == effects


def test_lumped_session_has_two_configurations_and_bends_only_the_looped_one() -> None:
    lumped = PRESETS["lumped"]
    straight, looped = make_session(lumped, "curvature", 40.0, 20.0, seed=101, matched=False)
    assert straight.metadata["configuration"] == "straight"
    assert looped.metadata["configuration"] == "looped"
    assert straight.metadata["catheter"] == "unit-101"
    none_s, none_l = make_session(lumped, "none", 40.0, 20.0, seed=101, matched=False)
    # same unit, same motion: without curvature the configurations differ only by noise
    d_none = np.abs(none_l.columns["tip1"] - none_s.columns["tip1"]).mean()
    d_curv = np.abs(looped.columns["tip1"] - straight.columns["tip1"]).mean()
    assert d_curv > 5 * d_none


def test_a_session_records_the_matched_protocol_in_each_configuration() -> None:
    recs = make_session(PRESETS["lumped"], "none", 40.0, 20.0, seed=101)
    protocols = [r for r in recs if "segments" in r.metadata]
    assert sorted(r.metadata["configuration"] for r in protocols) == ["looped", "straight"]
    series = series_from_recording(protocols[0], "p")
    assert series.segment is not None and len(series.segments) > 0


def test_segments_preset_has_the_coupling_off_in_its_none_units_and_its_simulator() -> None:
    segments = parse_plant_spec("segments")
    assert segments.build_unit(101, 0.1).settings.coupling == 0.0
    assert segments.build().settings.coupling == 0.0
    coupled = segments.build_unit(101, 0.1, "coupling", **segments.case_effects("coupling"))
    assert coupled.settings.coupling > 0.0


def test_segments_compliance_case_halves_the_units_tendon_stiffness() -> None:
    segments = PRESETS["segments"]
    none = segments.build_unit(101, 0.1)
    soft = segments.build_unit(101, 0.1, "compliance", **segments.case_effects("compliance"))
    for k in (0, 1):
        assert soft.knobs[k].tendon_stiffness_N == pytest.approx(
            0.5 * none.knobs[k].tendon_stiffness_N)
        assert soft.knobs[k].slack_pos_mm == none.knobs[k].slack_pos_mm


def test_coilpipe_preset_has_the_path_coupling_off_in_its_none_units_and_its_simulator() -> None:
    coilpipe = parse_plant_spec("coilpipe")
    assert coilpipe.build_unit(101, 0.1).shared.coupling_mm_per_rad2 == 0.0
    assert coilpipe.build().shared.coupling_mm_per_rad2 == 0.0
    coupled = coilpipe.build_unit(101, 0.1, "coupling", **coilpipe.case_effects("coupling"))
    assert coupled.shared.coupling_mm_per_rad2 > 0.0


def test_coilpipe_rate_and_creep_cases_scale_the_units_own_constants() -> None:
    coilpipe = PRESETS["coilpipe"]
    none = coilpipe.build_unit(102, 0.1)
    fast = coilpipe.build_unit(102, 0.1, "rate", **coilpipe.case_effects("rate"))
    slow = coilpipe.build_unit(102, 0.1, "creep", **coilpipe.case_effects("creep"))
    for k in (0, 1):
        assert fast.knobs[k].viscous_N_s_per_mm == pytest.approx(
            8.0 * none.knobs[k].viscous_N_s_per_mm)
        assert slow.knobs[k].bend_creep_time_s == pytest.approx(
            2.0 * none.knobs[k].bend_creep_time_s)
        assert fast.knobs[k].bend_creep_time_s == none.knobs[k].bend_creep_time_s


def test_stickslip_cases_scale_the_units_own_relaxation_and_coupling_is_not_run() -> None:
    stickslip = PRESETS["stickslip"]
    none = stickslip.build_unit(102, 0.1)
    fast = stickslip.build_unit(102, 0.1, "rate", **stickslip.case_effects("rate"))
    slow = stickslip.build_unit(102, 0.1, "creep", **stickslip.case_effects("creep"))
    for k in (0, 1):
        assert fast.knobs[k].creep_fast_share == pytest.approx(5.0 * none.knobs[k].creep_fast_share)
        assert slow.knobs[k].creep_slow_share == pytest.approx(1.5 * none.knobs[k].creep_slow_share)
        assert fast.knobs[k].creep_slow_share == none.knobs[k].creep_slow_share
    assert not stickslip.supports("coupling")


def test_twistshaft_coupling_moves_the_units_own_lumens_and_rate_creep_are_not_run() -> None:
    twist = PRESETS["twistshaft"]
    none = twist.build_unit(102, 0.1)
    coupled = twist.build_unit(102, 0.1, "coupling", **twist.case_effects("coupling"))
    for k in (0, 1):
        assert coupled.knobs[k].lumen_angle_error_deg == pytest.approx(
            4.5 * none.knobs[k].lumen_angle_error_deg)
        assert coupled.knobs[k].lumen_helix_deg == none.knobs[k].lumen_helix_deg
    assert not twist.supports("rate")
    assert not twist.supports("creep")


def test_screwrod_cases_scale_the_units_tendons_and_coupling_rate_are_not_run() -> None:
    screw = PRESETS["screwrod"]
    none = screw.build_unit(102, 0.1)
    creep = screw.build_unit(102, 0.1, "creep", **screw.case_effects("creep"))
    for k in (0, 1):
        assert creep.knobs[k].p.creep_time_s == pytest.approx(0.07 * none.knobs[k].p.creep_time_s)
        assert creep.knobs[k].p.creep_limit_mm == none.knobs[k].p.creep_limit_mm
    assert not screw.supports("coupling")
    assert not screw.supports("rate")


def test_nitinol_cases_scale_the_units_film_and_rope_and_coupling_creep_are_not_run() -> None:
    niti = PRESETS["nitinol"]
    none = niti.build_unit(102, 0.1)
    rate = niti.build_unit(102, 0.1, "rate", **niti.case_effects("rate"))
    soft = niti.build_unit(102, 0.1, "compliance", **niti.case_effects("compliance"))
    for k in (0, 1):
        assert rate.knobs[k].p.film_damping_N_s_per_mm == pytest.approx(
            5.0 * none.knobs[k].p.film_damping_N_s_per_mm)
        assert soft.knobs[k].p.tendon_stiffness_N == pytest.approx(
            0.5 * none.knobs[k].p.tendon_stiffness_N)
        assert rate.knobs[k].p.tendon_stiffness_N == none.knobs[k].p.tendon_stiffness_N
    assert not niti.supports("coupling")
    assert not niti.supports("creep")


def test_helixbelt_cases_scale_the_units_plane_error_and_rope_and_rate_creep_are_not_run(
) -> None:
    helix = PRESETS["helixbelt"]
    none = helix.build_unit(102, 0.1)
    coupled = helix.build_unit(102, 0.1, "coupling", **helix.case_effects("coupling"))
    soft = helix.build_unit(102, 0.1, "compliance", **helix.case_effects("compliance"))
    for k in (0, 1):
        assert coupled.knobs[k].plane_error_deg == pytest.approx(
            2.2 * none.knobs[k].plane_error_deg)
        assert soft.knobs[k].tendon_stiffness_N == pytest.approx(
            0.5 * none.knobs[k].tendon_stiffness_N)
        assert coupled.knobs[k].tendon_stiffness_N == none.knobs[k].tendon_stiffness_N
    assert helix.case_effects("curvature") == {"sheath_curvature_deg": 120.0}
    assert not helix.supports("rate")
    assert not helix.supports("creep")


def test_ratestate_cases_scale_the_units_ageing_and_rope_and_coupling_creep_are_not_run(
) -> None:
    rs = PRESETS["ratestate"]
    none = rs.build_unit(102, 0.1)
    rate = rs.build_unit(102, 0.1, "rate", **rs.case_effects("rate"))
    soft = rs.build_unit(102, 0.1, "compliance", **rs.case_effects("compliance"))
    for k in (0, 1):
        assert rate.knobs[k].ageing_b == pytest.approx(10.0 * none.knobs[k].ageing_b)
        assert soft.knobs[k].tendon_stiffness_N == pytest.approx(
            0.5 * none.knobs[k].tendon_stiffness_N)
        assert rate.knobs[k].tendon_stiffness_N == none.knobs[k].tendon_stiffness_N
    assert rs.case_effects("curvature") == {"sheath_curvature_deg": 120.0}
    assert 0.0 < rs.max_step_s < 0.02
    assert not rs.supports("coupling")
    assert not rs.supports("creep")


def test_a_plant_valid_at_short_steps_is_stepped_finely_and_read_at_the_rows() -> None:
    # the screwrod plant's walled knob overshoots at 20 ms steps (torque spikes of ~1000 N m)
    screw = PRESETS["screwrod"]
    _t, q = trajectory(36.0, 50.0)
    tip, cur = drive_plant(screw.build_unit(0, 0.0), q, 50.0, screw.max_step_s)
    rows = np.arange(len(q), dtype=float)
    fine = np.arange((len(q) - 1) * 10 + 1) / 10
    q_ms = np.stack([np.interp(fine, rows, q[:, j]) for j in (0, 1)], axis=1)
    tip_ms, _ = drive_plant(screw.build_unit(0, 0.0), q_ms, 500.0)
    assert np.abs(cur).max() < 1.0
    assert np.abs(tip - tip_ms[::10]).max() < 0.2


def test_a_case_the_data_plant_lacks_is_not_run(monkeypatch: pytest.MonkeyPatch) -> None:
    import tsmd.gap.crosstest as crosstest

    def no_session(*_a: object, **_k: object) -> None:
        raise AssertionError("a session was made for an effect the plant does not have")

    monkeypatch.setattr(crosstest, "make_session", no_session)
    assert not PRESETS["segments"].supports("creep")
    result = crosstest.run_crosstest(PRESETS["segments"], PRESETS["capstan"], ["creep"],
                                     [240.0], [101])
    assert result.cases == []


def test_selftest_says_which_case_the_data_plant_cannot_make(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from tsmd import cli

    code = cli.main(["gap", "selftest", "--data-plant", "segments", "--sim-plant", "capstan",
                     "--cases", "creep", "--seeds", "101", "--out", str(tmp_path)])
    assert code == 0
    assert "creep: not run" in capsys.readouterr().out
