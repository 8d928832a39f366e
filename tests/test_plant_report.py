"""The plant report prints the sweep signature and refuses bad parameters in one line."""

from __future__ import annotations

from pathlib import Path

import pytest

from drivers.plant.report import main


def test_report_prints_both_knobs_and_writes_the_figure(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "sweep.png"
    assert main(["--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert out.count("dead zone D_pos/D_neg") == 2
    assert "us/step" in out
    assert png.stat().st_size > 10_000


def test_report_refuses_an_unknown_parameter(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--set", "bogus=1"]) == 2
    err = capsys.readouterr().err
    assert "bogus" in err
    assert "Traceback" not in err
