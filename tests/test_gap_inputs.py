"""Bad input to `tsmd gap` gives one line naming the problem, and computed figures are kept."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from support.gap import StandInPlant, make_recording

from tsmd import cli
from tsmd.gap import report
from tsmd.gap.data import make_split, series_from_recording
from tsmd.gap.diagnose import diagnose
from tsmd.gap.errors import GapError
from tsmd.gap.fit import ParamSpec
from tsmd.gap.result import GapConfig
from tsmd.recording import Recording, write_recording

START = {"slack_deg": 15.0, "play_deg": 8.0, "friction_Nm": 0.01}
FAST = GapConfig(fit_specs=(ParamSpec("slack_deg", 5.0, 30.0),), fit_max_rows=600,
                 rank_max_rows=800, n_boot=200, base_evals=8, polish_evals=2, refine_evals=2,
                 joint_top=0, candidate_evals=3)


def _rec(seed: int = 3, duration_s: float = 60.0) -> Recording:
    return make_recording(duration_s=duration_s, rate_hz=20.0, seed=seed)


def _cli_error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    code = cli.main(["gap", *argv])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    return err


def test_whole_recordings_held_out_give_a_full_report(tmp_path: Path) -> None:
    a, b = series_from_recording(_rec(1), "a.csv"), series_from_recording(_rec(2), "b.csv")
    result = diagnose([a, b], lambda p: StandInPlant(**p), START,
                      GapConfig(**{**vars(FAST), "holdout": ("b.csv",)}))
    md, js = report.write_report(result, tmp_path, "a+b")
    data = json.loads(js.read_text())
    assert data["plot_error"] is None and set(data["plots"]) >= {"timeseries", "candidates"}
    assert np.isfinite(data["before"]["tip1_rmse_deg"])
    assert "b.csv" in md.read_text()


def test_a_failing_plot_stage_keeps_the_figures(tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    result = diagnose([series_from_recording(_rec(), "r")], lambda p: StandInPlant(**p), START,
                      FAST)

    def broken(*_args: object, **_kw: object) -> dict[str, str]:
        raise RuntimeError("no display")

    monkeypatch.setattr(report, "plots", broken)
    md, js = report.write_report(result, tmp_path, "r")
    data = json.loads(js.read_text())
    assert data["verdict"] == result.verdict and "no display" in data["plot_error"]
    assert "Plots not drawn" in md.read_text()


def test_unknown_held_out_name_is_one_line(tmp_path: Path,
                                           capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "a.csv"
    write_recording(path, _rec())
    err = _cli_error([str(path), "--holdout", "a.csv,zz.csv"], capsys)
    assert "zz.csv" in err and "match no recording" in err


def test_nan_in_a_recording_is_one_line(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    rec = _rec()
    rec.columns["cur2"][40] = np.nan
    path = tmp_path / "n.csv"
    write_recording(path, rec)
    assert "'cur2'" in _cli_error([str(path)], capsys)


def test_non_increasing_time_is_one_line(tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    rec = _rec()
    rec.columns["t"][50] = rec.columns["t"][49]
    path = tmp_path / "t.csv"
    write_recording(path, rec)
    assert "not strictly increasing" in _cli_error([str(path)], capsys)


def test_missing_column_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "m.csv"
    path.write_text("t,pos1,pos2,cur1,tip1,tip2\n" + "".join(
        f"{i * 0.1},{i},0,0,{i},0\n" for i in range(300)))
    assert "cur2" in _cli_error([str(path)], capsys)


def test_held_out_data_without_tip_are_refused() -> None:
    sa, sb = series_from_recording(_rec(1), "a"), series_from_recording(_rec(2), "b")
    sb = type(sb)(**{**vars(sb), "channel_valid": (False, False, True, True)})
    with pytest.raises(GapError, match="no tip measurement"):
        make_split([sa, sb], ["b"])


def test_a_channel_measured_only_in_held_out_data_is_refused() -> None:
    sa, sb = series_from_recording(_rec(1), "a"), series_from_recording(_rec(2), "b")
    sa = type(sa)(**{**vars(sa), "channel_valid": (True, False, True, True)})
    with pytest.raises(GapError, match="tip2 is measured in the held-out data"):
        make_split([sa, sb], ["b"])
