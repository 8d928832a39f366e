"""Tendon compliance named from the protocol's reversals against the model's data sheet."""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

import numpy as np
import pytest
from numpy.typing import NDArray

from tsmd import cli
from tsmd.gap import compliance, crosstest
from tsmd.gap.contrast import product_reference
from tsmd.gap.crosstest import make_session
from tsmd.gap.data import GapSeries, series_from_recording
from tsmd.gap.presets import PRESETS
from tsmd.gap.signature import SignatureScore
from tsmd.gap.structure import rank_scores
from tsmd.recording import Recording, write_recording

Arr = NDArray[np.float64]
RATE_HZ = 50.0


def _play(x: Arr, half_width: float) -> Arr:
    out = np.empty(len(x))
    y = float(x[0])
    for k, xk in enumerate(x.tolist()):
        y = min(max(y, xk - half_width), xk + half_width)
        out[k] = y
    return out


@pytest.mark.parametrize("gain", [0.4, 1.0])
def test_lost_motion_is_the_play_whatever_the_releasing_gain(gain: float) -> None:
    travel = compliance.TRAVEL_GRID_DEG
    curve = gain * np.maximum(travel - 6.0, 0.0)
    assert compliance._onset(curve) == pytest.approx(6.0, abs=0.05)


def test_a_return_within_one_knob_sample_reads_within_that_sample() -> None:
    # the knob moves 0.4 deg per sample and the tip returns 2 deg within one sample
    x = np.arange(0.0, 40.0, 0.4)
    tip = np.clip((x - 6.1) * 5.0, 0.0, None)
    curve = np.interp(compliance.TRAVEL_GRID_DEG, x, tip)
    assert 6.0 - 1e-9 <= compliance._onset(curve) <= 6.4


def test_a_return_smaller_than_the_threshold_is_read_at_its_own_scale() -> None:
    # a soft tendon at the loop amplitude leaves the tip barely out of its dead zone
    travel = compliance.TRAVEL_GRID_DEG
    curve = np.clip(travel - 9.0, 0.0, 0.9)
    assert compliance._onset(curve) == pytest.approx(9.0, abs=0.05)


def test_no_return_gives_no_lost_motion() -> None:
    assert np.isnan(compliance._onset(np.full(len(compliance.TRAVEL_GRID_DEG), 0.1)))


def test_the_null_spread_grows_with_the_repeats_scatter() -> None:
    rng = np.random.default_rng(0)
    travel = compliance.TRAVEL_GRID_DEG

    def reversals(scatter_deg: float) -> compliance.Reversals:
        onsets = 6.0 + scatter_deg * rng.standard_normal(8)
        ret = np.array([np.maximum(travel - o, 0.0) for o in onsets])
        cur = np.zeros_like(ret)
        return compliance.Reversals(ret, cur, np.full(8, 0.05), np.full(8, 40.0),
                                    np.zeros(8, dtype=np.int64))

    rows = np.arange(8)
    tight = compliance._jackknife_var(reversals(0.05), rows)[0]
    loose = compliance._jackknife_var(reversals(0.5), rows)[0]
    assert loose > 20.0 * tight


@functools.cache
def _protocol_recordings(unit: int, case: str, unit_variation: float) -> list[Recording]:
    recs = make_session(PRESETS["capstan"], case, 4.0, RATE_HZ, unit,
                        unit_variation=unit_variation)
    return [r for r in recs if "segments" in r.metadata]


@functools.cache
def _protocol_series(unit: int, case: str, unit_variation: float = 0.1) -> list[GapSeries]:
    return [series_from_recording(r, f"{case}-{i}")
            for i, r in enumerate(_protocol_recordings(unit, case, unit_variation))]


@functools.cache
def _sheet() -> tuple[float, float]:
    ref = compliance.reference_deg_per_A(_protocol_series(0, "none", 0.0))
    assert ref is not None
    return ref


def test_doubled_tendon_compliance_is_named_against_the_data_sheet() -> None:
    score = compliance.compliance_score(_protocol_series(5, "compliance"), _sheet(), 7)
    assert score is not None and score.significant
    assert score.share > 0.5


def test_a_unit_without_the_effect_is_not_named() -> None:
    score = compliance.compliance_score(_protocol_series(5, "none"), _sheet(), 7)
    assert score is not None and not score.significant


def test_a_current_sensor_lag_does_not_read_as_compliance() -> None:
    score = compliance.compliance_score(_protocol_series(5, "sensor"), _sheet(), 7)
    assert score is not None and not score.significant


def test_a_knob_whose_tip_never_returns_leaves_the_figure_to_the_other_knob() -> None:
    # a soft tendon can leave one knob's tip inside its dead zone at the loop amplitude
    flat = []
    for s in _protocol_series(5, "compliance"):
        tip = s.tip_deg.copy()
        tip[:, 0] = 0.0
        flat.append(dataclasses.replace(s, tip_deg=tip))
    assert compliance.reference_deg_per_A(flat) is None
    score = compliance.compliance_score(flat, _sheet(), 7)
    assert score is not None and score.significant


def test_the_protocols_slow_reversals_fill_both_loads_on_both_sides_of_each_knob() -> None:
    # the figure's loads follow the protocol's design: a moved dwell must still be read
    for knob in (0, 1):
        at = compliance.reversals(_protocol_series(5, "none"), knob).at_deg
        for level in compliance.LEVELS_DEG:
            for side in (1.0, -1.0):
                near = np.abs(at - side * level) <= compliance.LEVEL_BAND_DEG
                assert int(near.sum()) >= compliance.MIN_PER_LEVEL


def test_recordings_without_the_protocol_give_no_figure() -> None:
    plain = [GapSeries(s.name, s.t_s, s.knob_deg, s.current_A, s.tip_deg, s.knob_source)
             for s in _protocol_series(5, "none")]
    assert compliance.reference_deg_per_A(plain) is None
    assert compliance.compliance_score(plain, _sheet(), 7) is None


def test_a_significant_compliance_ranks_after_a_significant_matched_effect() -> None:
    def score(name: str, share: float) -> SignatureScore:
        return SignatureScore(name, name, "", share, (share, share), True, share, 0.0)

    ranked = rank_scores([score("compliance", 0.95), score("coupling", 0.7)])
    assert [s.name for s in ranked] == ["coupling", "compliance"]


def test_the_sheet_command_prints_the_figure_the_diagnosis_takes(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    paths = []
    for i, rec in enumerate(_protocol_recordings(0, "none", 0.0)):
        paths.append(str(tmp_path / f"ref{i}.csv"))
        write_recording(paths[-1], rec)
    assert cli.main(["gap", "sheet", *paths]) == 0
    out = capsys.readouterr().out
    ref = _sheet()
    assert f"--compliance-sheet {ref[0]:.4g},{ref[1]:.4g}" in out


@pytest.mark.parametrize("argv", [["sheet"], ["x.csv", "--compliance-sheet", "12"],
                                  ["x.csv", "--compliance-sheet", "0,4"]])
def test_a_bad_sheet_request_is_one_line(argv: list[str], tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    if argv[0] == "x.csv":
        argv = [str(_written(tmp_path)), *argv[1:]]
    code = cli.main(["gap", *argv, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err


def _written(tmp_path: Path) -> Path:
    path = tmp_path / "x.csv"
    write_recording(path, _protocol_recordings(0, "none", 0.0)[0])
    return path


def test_a_data_sheet_measured_on_a_scattered_unit_differs_from_the_nominal_one() -> None:
    nominal = crosstest.datasheet_reference(PRESETS["capstan"], RATE_HZ)
    scattered = crosstest.datasheet_reference(PRESETS["capstan"], RATE_HZ, unit=201)
    assert nominal is not None and scattered is not None
    assert scattered != pytest.approx(nominal, rel=1e-3)
    assert scattered == pytest.approx(nominal, rel=1.0 / 3.0)


@pytest.mark.parametrize("unit", ["5", "-1"])
def test_a_data_sheet_unit_that_is_scored_or_negative_is_one_line(
        unit: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = cli.main(["gap", "selftest", "--data-plant", "capstan", "--sim-plant", "capstan",
                     "--seeds", "5", "--sheet-unit", unit, "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "data-sheet unit" in err


@pytest.mark.parametrize("units", ["0,5", "-1"])
def test_a_reference_unit_that_is_scored_or_negative_is_one_line(
        units: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = cli.main(["gap", "selftest", "--data-plant", "capstan", "--sim-plant", "capstan",
                     "--seeds", "5", "--reference-units", units, "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "reference unit" in err


@pytest.mark.parametrize("kind", ["no-segments", "missing"])
def test_a_model_reference_without_the_protocol_is_one_line(
        kind: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    data = _written(tmp_path)
    ref = tmp_path / "ref.csv"
    if kind == "no-segments":
        rec = _protocol_recordings(0, "none", 0.0)[0]
        cols = {k: v for k, v in rec.columns.items() if k != "segment"}
        meta = {k: v for k, v in rec.metadata.items() if k != "segments"}
        write_recording(ref, Recording(cols, meta))
    code = cli.main(["gap", str(data), "--model-reference", str(ref),
                     "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err


def _scaled(series: list[GapSeries], figure_factor: float) -> list[GapSeries]:
    """The same recordings read with the current scaled: the figure times ``figure_factor``."""
    return [dataclasses.replace(s, current_A=s.current_A / figure_factor) for s in series]


def test_a_sheet_from_one_unit_has_no_allowance_and_from_scattered_units_their_spread() -> None:
    unit = _protocol_series(0, "none", 0.0)
    one = compliance.sheet_from_units([unit])
    scattered = compliance.sheet_from_units(
        [unit, _scaled(unit, 1.15), _scaled(unit, 1.0 / 1.15)])
    assert one is not None and scattered is not None
    assert one.allowance_log_var == (0.0, 0.0)
    assert min(scattered.allowance_log_var) > 0.01
    assert scattered.figure_deg_per_A == pytest.approx(one.figure_deg_per_A, rel=0.02)


def test_a_unit_within_its_models_spread_is_not_named_but_one_beyond_it_is() -> None:
    unit = _protocol_series(0, "none", 0.0)
    one = compliance.sheet_from_units([unit])
    scattered = compliance.sheet_from_units(
        [unit, _scaled(unit, 1.15), _scaled(unit, 1.0 / 1.15)])
    assert one is not None and scattered is not None
    softer = _scaled(_protocol_series(5, "none"), 1.4)
    named = compliance.compliance_score(softer, one, 7)
    within = compliance.compliance_score(softer, scattered, 7)
    beyond = compliance.compliance_score(_scaled(_protocol_series(5, "none"), 2.5), scattered, 7)
    assert named is not None and named.significant
    assert within is not None and not within.significant
    assert beyond is not None and beyond.significant


def test_the_sheets_own_noise_widens_the_figures_bound() -> None:
    series = _scaled(_protocol_series(5, "none"), 1.4)
    exact = compliance.compliance_score(series, compliance.ComplianceSheet(_sheet()), 7)
    noisy = compliance.compliance_score(
        series, compliance.ComplianceSheet(_sheet(), noise_log_var=(0.05, 0.05)), 7)
    assert exact is not None and noisy is not None
    assert exact.significant and not noisy.significant


def test_a_model_reference_from_several_units_carries_their_compliance_sheet() -> None:
    units = [dataclasses.replace(s, catheter=f"unit-{u}")
             for u in (0, 6) for s in _protocol_series(u, "none")]
    reference = product_reference(units)
    assert reference.units == 2 and reference.compliance is not None
    assert all(np.isfinite(reference.compliance.figure_deg_per_A))


def test_a_measured_spread_is_not_counted_twice_but_an_unknown_one_is_the_tolerance() -> None:
    # x1.52, lower bound about x1.13: beyond a spread measured as nil, not the tolerance
    softer = _scaled(_protocol_series(5, "none"), 1.5)
    noise = (0.03, 0.03)
    one = compliance.ComplianceSheet(_sheet(), noise_log_var=noise, units=1)
    several = compliance.ComplianceSheet(_sheet(), noise_log_var=noise, units=5)
    from_one = compliance.compliance_score(softer, one, 7)
    from_several = compliance.compliance_score(softer, several, 7)
    assert from_one is not None and from_several is not None
    assert from_several.significant and not from_one.significant


def _scaled_knobs(series: list[GapSeries], factors: tuple[float, float]) -> list[GapSeries]:
    """The same recordings with each knob's figure times its factor."""
    return [dataclasses.replace(s, current_A=s.current_A / np.array(factors)) for s in series]


def test_a_unit_read_above_the_sheet_on_one_knob_only_is_not_named() -> None:
    unit = _protocol_series(5, "none")
    both = compliance.compliance_score(_scaled_knobs(unit, (2.0, 2.0)), _sheet(), 7)
    one = compliance.compliance_score(_scaled_knobs(unit, (2.0, 0.6)), _sheet(), 7)
    assert both is not None and both.significant
    assert one is not None and not one.significant
