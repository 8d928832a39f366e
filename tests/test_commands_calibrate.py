"""`tsmd calibrate`: user errors are one line and exit code 2; offline identification prints."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tsmd.cli import main
from tsmd.tee import default_tee_dir

DEVICE = str(Path(__file__).resolve().parent.parent / "profiles" / "devices"
             / "sim-catheter.yaml")


def test_a_malformed_recording_is_one_line_and_exit_2(tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y\n1,2\n")
    code = main(["calibrate", "--catheter", "c1", "--device", DEVICE,
                 "--profiles", str(tmp_path), "--from-recording", str(bad)])
    err = capsys.readouterr().err
    assert code == 2
    assert "missing column" in err and len(err.strip().splitlines()) == 1
    assert not list(tmp_path.glob("*.yaml"))


def test_an_unreachable_daemon_is_named(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["calibrate", "--catheter", "c1", "--socket", str(tmp_path / "none.sock")])
    assert code == 2
    assert "cannot reach the daemon" in capsys.readouterr().err


def test_fast_needs_the_simulator_or_recordings(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["calibrate", "--catheter", "c1", "--fast", "--socket", "/x"]) == 2
    assert "--fast needs --sim" in capsys.readouterr().err


@pytest.mark.realdata
@pytest.mark.skipif(not default_tee_dir().is_dir(), reason="no TEE data")
def test_tee_files_are_identified_and_the_profile_refused(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    files = sorted(default_tee_dir().glob("motor*_current60__First_acquisition.csv"))
    code = main(["calibrate", "--catheter", "tee", "--device", DEVICE, "--profiles",
                 str(tmp_path), "--from-recording", *map(str, files)])
    captured = capsys.readouterr()
    assert "| phi1 sweep, phi2 at +0 deg | phi1 |" in captured.out
    assert code == 2 and "calibration refused" in captured.err
    assert not list(tmp_path.glob("*.yaml"))


@pytest.mark.realdata
@pytest.mark.skipif(not default_tee_dir().is_dir(), reason="no TEE data")
def test_tee_files_get_a_report_of_what_they_give_and_lack(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    files = sorted(default_tee_dir().glob("motor1_current60__*.csv"))
    code = main(["calibrate", "--catheter", "tee", "--device", DEVICE, "--profiles",
                 str(tmp_path), "--from-recording", *map(str, files)])
    out = capsys.readouterr().out
    assert code == 2
    # The three acquisitions of the same grid point are pooled: 3 half-cycles per value.
    assert re.search(r"\| phi1, other \+0 \| -?\d+\.\d \+- \d+\.\d \(n=3\)", out)
    assert "a profile needs >= 2 angles including 0" in out
    assert "phi2: no sweep" in out
    assert "no B_neg:" in out


def test_without_device_or_config_the_missing_device_model_is_named(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rec = tmp_path / "sweep.csv"
    rec.write_text("x,y\n1,2\n")
    code = main(["calibrate", "--catheter", "c1", "--profiles", str(tmp_path),
                 "--from-recording", str(rec)])
    err = capsys.readouterr().err
    assert code == 2
    assert "no device model" in err and len(err.strip().splitlines()) == 1


@pytest.fixture
def rig_must_not_move(monkeypatch: pytest.MonkeyPatch) -> None:
    """A check that belongs before the sweeps fails the test if the simulated rig is built."""
    def refuse(*_args: object, **_kwargs: object) -> None:
        raise AssertionError("the rig was started before the save target was checked")
    monkeypatch.setattr("tsmd.commands.calibrate.LockstepRunner", refuse)


@pytest.mark.usefixtures("rig_must_not_move")
def test_a_bad_catheter_id_is_refused_before_anything_moves(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["calibrate", "--catheter", "../etc", "--sim", "--profiles", str(tmp_path)])
    assert code == 2
    assert "catheter id '../etc'" in capsys.readouterr().err


@pytest.mark.usefixtures("rig_must_not_move")
def test_an_unwritable_profiles_directory_is_refused_before_anything_moves(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    code = main(["calibrate", "--catheter", "c1", "--sim", "--profiles", str(blocker / "dir")])
    err = capsys.readouterr().err
    assert code == 2
    assert "cannot write" in err and len(err.strip().splitlines()) == 1
