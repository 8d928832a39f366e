"""The whole diagnosis on stand-in data: its three answers, the report, and the command line."""

from __future__ import annotations

import argparse
import dataclasses
import functools
import json
from pathlib import Path

import numpy as np
import pytest
from support.gap import StandInPlant, make_recording

from tsmd.commands import gap as gap_command
from tsmd.gap.data import series_from_recording
from tsmd.gap.diagnose import diagnose
from tsmd.gap.errors import GapError
from tsmd.gap.fit import ParamSpec
from tsmd.gap.report import write_report
from tsmd.gap.result import GapConfig, GapResult
from tsmd.recording import Recording, write_recording

SPECS = (ParamSpec("slack_deg", 5.0, 30.0), ParamSpec("play_deg", 0.0, 20.0),
         ParamSpec("friction_Nm", 0.0, 0.05))
START = {"slack_deg": 15.0, "play_deg": 8.0, "friction_Nm": 0.01}
CONFIG = GapConfig(fit_specs=SPECS, fit_max_rows=1200, rank_max_rows=2000, n_boot=500,
                   base_evals=34, polish_evals=10, refine_evals=6, joint_top=0,
                   method="candidates")


@functools.cache
def _lagged() -> GapResult:
    return _diagnose(_rec(lag_s=0.2))


def _diagnose(rec: Recording) -> GapResult:
    return diagnose([series_from_recording(rec, "r")], lambda p: StandInPlant(**p), START,
                    CONFIG)


def _rec(**kw: float) -> Recording:
    return make_recording(duration_s=200.0, rate_hz=20.0, seed=3, **kw)


def test_data_without_unmodelled_effect_gives_none_significant() -> None:
    result = _diagnose(_rec())
    assert result.verdict == "none significant"
    assert result.top == []
    assert result.gap_ratio[0] < 1.3


def test_current_lag_is_identified_as_current_sensor_dynamics() -> None:
    result = _lagged()
    assert result.top == ["sensor"]
    top = result.candidates[0]
    assert top.significant and top.ci[0] > 0
    assert result.after_top is not None
    assert result.after_top["cur1_rmse_A"] < 0.9 * result.before["cur1_rmse_A"]


def test_tip_drift_is_identified_and_shrinks_the_held_out_tip_error() -> None:
    result = _diagnose(_rec(tip_drift_deg_s=0.01))
    assert result.verdict == "identified: drift"
    assert result.after_top is not None
    assert result.after_top["tip1_rmse_deg"] < 0.5 * result.before["tip1_rmse_deg"]


def test_joint_refit_rescores_the_best_screened_candidates() -> None:
    cfg = dataclasses.replace(CONFIG, joint_top=2, refine_evals=6)
    result = diagnose([series_from_recording(_rec(tip_drift_deg_s=0.01), "r")],
                      lambda p: StandInPlant(**p), START, cfg)
    assert [c.stage for c in result.candidates[:2]] == ["joint", "joint"]
    assert result.top == ["drift"]


def test_a_disturbance_outside_the_catalogue_is_unexplained() -> None:
    rec = _rec()
    t = rec.columns["t"]
    # patient motion: breathing moves the tip by +-4 deg; no candidate models it
    rec.columns["tip1"] = rec.columns["tip1"] + 4.0 * np.sin(2 * np.pi * t / 4.3)
    result = _diagnose(rec)
    assert result.verdict == "unexplained"
    assert result.gap_ratio[0] > 5


def test_where_breakdown_points_at_the_other_knob_for_coupling() -> None:
    result = _diagnose(_rec(coupling_deg=15.0))
    shares = result.where_shares["tip"]
    assert shares["other_knob"] > shares["time_in_run"]
    assert result.top and result.top[0] == "coupling"


def test_report_writes_markdown_json_and_plots_with_the_same_figures(tmp_path: Path) -> None:
    result = _lagged()
    md, js = write_report(result, tmp_path, "lagged")
    data = json.loads(js.read_text())
    assert data["verdict"] == result.verdict
    assert data["before"]["cur1_rmse_A"] == pytest.approx(result.before["cur1_rmse_A"])
    text = md.read_text()
    assert result.verdict in text and "## Where the gap is" in text
    for name in data["plots"].values():
        assert (tmp_path / name).stat().st_size > 1000


# --- command line -------------------------------------------------------------------------------

def _write(tmp_path: Path, rec: Recording, name: str = "r.csv") -> Path:
    path = tmp_path / name
    write_recording(path, rec)
    return path


def _run(argv: list[str]) -> int:
    parser = argparse.ArgumentParser()
    gap_command.add_arguments(parser)
    return gap_command.main(parser.parse_args(argv))


def test_cli_refuses_a_recording_without_tip(tmp_path: Path) -> None:
    rec = _rec()
    rec.columns["tip1"][:] = np.nan
    rec.columns["tip2"][:] = np.nan
    path = _write(tmp_path, rec)
    with pytest.raises(GapError, match="no tip measurement"):
        _run([str(path), "--out", str(tmp_path / "o")])


def test_cli_names_a_missing_column(tmp_path: Path) -> None:
    path = tmp_path / "bad.csv"
    path.write_text("t,pos1,pos2,cur1,tip1,tip2\n" + "".join(
        f"{i * 0.1},{i},0,0,{i},0\n" for i in range(300)))
    with pytest.raises(GapError, match="missing column 'cur2'"):
        _run([str(path)])


def test_cli_refuses_a_bad_fit_spec(tmp_path: Path) -> None:
    path = _write(tmp_path, _rec())
    with pytest.raises(GapError, match="LO < HI"):
        _run([str(path), "--fit", "slack_deg=9:3"])


def test_cli_diagnoses_with_a_plugged_plant(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    path = _write(tmp_path, _rec(lag_s=0.2))
    out = tmp_path / "report"
    code = _run([str(path), "--plant", "support.gap:make_stand_in",
                 "--params", json.dumps(START), "--fit", "slack_deg=5:30",
                 "--fit", "play_deg=0:20", "--fit-rows", "1000", "--out", str(out)])
    assert code == 0
    assert "verdict:" in capsys.readouterr().out
    data = json.loads((out / "gap_report.json").read_text())
    assert data["plant"] == "support.gap:make_stand_in"
    assert data["candidates"][0]["name"] == "sensor"
