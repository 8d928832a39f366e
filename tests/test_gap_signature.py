"""The signature method: base mismatch absorbed, effects named by the condition they depend on."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from support.gap import StandInPlant, make_recording

from tsmd.gap.data import make_split, series_from_recording
from tsmd.gap.diagnose import diagnose
from tsmd.gap.layer import SigData, play_bank, sensitivity, stack_views
from tsmd.gap.model import build_views
from tsmd.gap.result import GapConfig, GapResult
from tsmd.gap.signature import _shift, _slow_wave
from tsmd.recording import Recording

# the simulator is the stand-in with other physics than the data's (no base fit at all): a
# structural mismatch of dead zone, play and slope
SIM = {"slack_deg": 10.0, "play_deg": 4.0, "slope": 1.0}
FAST = GapConfig(fit_specs=(), rank_max_rows=2000, n_boot=500, n_surrogates=4)


def _rec(seed: int = 3, config: str = "", **kw: float) -> Recording:
    rec = make_recording(duration_s=200.0, rate_hz=20.0, seed=seed, tip_noise_deg=0.1, **kw)
    if config:
        rec.metadata["configuration"] = config
    return rec


def _diagnose(*recs: Recording) -> GapResult:
    series = [series_from_recording(r, f"r{i}") for i, r in enumerate(recs)]
    return diagnose(series, lambda p: StandInPlant(**{**SIM, **p}), {}, FAST)


@functools.cache
def _plain() -> GapResult:
    return _diagnose(_rec())


@functools.cache
def _drifted() -> GapResult:
    return _diagnose(_rec(tip_drift_deg_s=0.01))


def test_play_bank_holds_each_output_until_the_input_turns_by_its_width() -> None:
    x = np.array([0.0, 10.0, 8.0, 4.0, 12.0])
    out = play_bank(x, (0.0, 3.0))
    np.testing.assert_allclose(out[:, 0], x)
    np.testing.assert_allclose(out[:, 1], [0.0, 7.0, 7.0, 7.0, 9.0])


def test_sensitivity_is_the_slope_when_loaded_and_zero_in_the_dead_zone() -> None:
    x = np.concatenate([np.linspace(0, 60, 121), np.linspace(60, 0, 121)[1:]])
    pred = 1.3 * np.sign(x) * np.maximum(np.abs(x) - 20.0, 0.0)
    d = SigData.__new__(SigData)
    d.segments = [slice(0, len(x))]
    g = sensitivity(d, pred, x)
    assert g[np.abs(x - 40) < 10].min() == pytest.approx(1.3)
    assert np.abs(g[(x > 2) & (x < 18)]).max() == pytest.approx(0.0)


def test_the_structural_layer_absorbs_most_of_a_different_base_physics() -> None:
    result = _plain()
    assert result.structure is not None and result.structure["layer_absorbs"] > 0.95
    assert result.verdict != "none significant"


KNOWN_CORNER_LIMIT = (
    "the stand-in's loop has sharp corners the layer's play/dead-zone grid does not hit; the "
    "residual at the corners grows with the sweep speed and is named rate (docs/gap.md, Limits)")


@pytest.mark.xfail(strict=True, reason=KNOWN_CORNER_LIMIT)
def test_a_different_base_physics_alone_is_not_called_an_effect() -> None:
    assert _plain().top == []


def test_coupling_on_top_of_a_base_mismatch_is_identified() -> None:
    result = _diagnose(_rec(coupling_deg=15.0))
    assert result.top == ["coupling"]
    assert result.after_top is not None and result.structure is not None
    layer = result.structure["figures"]["layer"]
    assert result.after_top["tip1_rmse_deg"] < 0.8 * layer["tip1_rmse_deg"]


def test_current_lag_on_top_of_a_base_mismatch_is_sensor_dynamics() -> None:
    result = _diagnose(_rec(lag_s=0.2))
    assert result.top == ["sensor"]


def test_a_drift_in_time_gains_more_than_its_slow_wave_surrogates() -> None:
    result = _drifted()
    drift = next(s for s in (result.structure or {})["signatures"] if s["name"] == "drift")
    assert drift["share"] > 0.05 and drift["ci"][0] > 0


@pytest.mark.xfail(strict=True, reason=KNOWN_CORNER_LIMIT)
def test_a_drift_in_time_is_named_drift() -> None:
    assert _drifted().top == ["drift"]


def test_a_configuration_that_changes_the_physics_is_named_curvature() -> None:
    a = _rec(seed=3, config="straight")
    b = _rec(seed=4, config="looped", play_deg=16.0)
    result = _diagnose(a, b)
    assert result.top == ["curvature"]
    assert result.structure is not None
    assert result.structure["configurations"] == ["looped", "straight"]


def test_without_configuration_labels_curvature_is_not_tried() -> None:
    names = [s["name"] for s in (_plain().structure or {})["signatures"]]
    assert "curvature" not in names and "coupling" in names


def test_report_figures_carry_intervals_around_each_rmse() -> None:
    fig = (_plain().structure or {})["figures"]["layer"]
    assert fig["tip1_rmse_lo_deg"] <= fig["tip1_rmse_deg"] <= fig["tip1_rmse_hi_deg"]


def test_surrogate_conditions_keep_the_values_but_lose_the_timing() -> None:
    series = [series_from_recording(_rec(), "r")]
    split = make_split(series, 0.3)
    views = build_views(series, split, [4], "fit")
    for v in views:
        v.base_tip, v.base_torque = v.series.tip_deg[v.rows], v.series.current_A[v.rows]
    d = stack_views(views, [""])
    shifted = _shift(d, d.knob, np.random.default_rng(0))
    np.testing.assert_allclose(np.sort(shifted[:, 0]), np.sort(d.knob[:, 0]))
    assert abs(np.corrcoef(shifted[:, 1], d.knob[:, 1])[0, 1]) < 0.9
    wave = _slow_wave(d, np.random.default_rng(1))
    assert wave.min() >= -1 and wave.max() <= 1 and np.ptp(wave) > 0.5


def test_header_configuration_and_catheter_reach_the_series() -> None:
    rec = _rec(config="looped")
    rec.metadata["catheter"] = "tee-7"
    s = series_from_recording(rec, "r")
    assert (s.config, s.catheter) == ("looped", "tee-7")
    rec.metadata.pop("configuration")
    rec.metadata["sheath_shape"] = "U loop"
    assert series_from_recording(rec, "r").config == "U loop"
