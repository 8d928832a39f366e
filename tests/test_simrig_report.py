"""The plant report prints the sweep signature and refuses bad parameters in one line."""

from __future__ import annotations

from pathlib import Path

import pytest

from simrig.plants.capstan.tendon_sheath import make_tendon_sheath_plant
from simrig.report import main, run_sweep, signature


def test_report_prints_both_knobs_and_writes_the_figure(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "sweep.png"
    assert main(["--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert out.count("dead zone D_pos/D_neg") == 2
    assert out.count("torque settled after") == 2
    assert "us/step" in out
    assert png.stat().st_size > 10_000


def test_report_refuses_an_unknown_parameter(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--set", "bogus=1"]) == 2
    err = capsys.readouterr().err
    assert "bogus" in err
    assert "Traceback" not in err


def test_report_says_where_the_torque_settles_after_a_reversal() -> None:
    """About the backlash on the straight handle, a few degrees on a routed one."""
    straight = signature(run_sweep(make_tendon_sheath_plant(), 0))
    routed = signature(
        run_sweep(make_tendon_sheath_plant(knobs=[{"routing_wrap_deg": 360.0}, {}]), 0)
    )
    assert straight.torque_settled_deg > 0.7 * straight.dz_bl.backlash_pos_deg
    assert routed.torque_settled_deg < 0.3 * routed.dz_bl.backlash_pos_deg


def test_report_routing_study_prints_each_wrap_and_writes_the_figure(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    png = tmp_path / "routing.png"
    assert main(["--routing", str(png)]) == 0
    lines = capsys.readouterr().out.splitlines()
    i = next(n for n, line in enumerate(lines) if line.startswith("knob 1 per routing_wrap_deg"))
    rows = [[float(v) for v in line.split()] for line in lines[i + 1 : i + 5]]
    assert [r[0] for r in rows] == [0.0, 90.0, 180.0, 360.0]
    settled = [r[4] for r in rows]
    assert settled == sorted(settled, reverse=True)  # more routing, earlier collapse
    assert png.stat().st_size > 10_000
