"""The TEE acquisition converter: real files (skipped when absent) and malformed input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tsmd.calibration import identify_recording
from tsmd.recording import RecordingError, read_recording, write_recording
from tsmd.tee import (
    CURRENT_A_PER_RAW,
    DEFAULT_STEPS_PER_KNOB_DEG,
    default_tee_dir,
    load_tee_acquisition,
)

TEE_DIR = default_tee_dir()
HEADER = ("," + ",".join([
    "Motor position", "Current", "Tip position x", "Tip position y", "Tip position z",
    "Tip orientation x", "Tip orientation y", "Tip orientation z", "Tip orientation w",
    "Base position x", "Base position y", "Base position z",
    "Base orientation x", "Base orientation y", "Base orientation z", "Base orientation w"]))


def _real_files() -> list[Path]:
    if not TEE_DIR.is_dir():
        return []
    return sorted(TEE_DIR.glob("motor*_current60__*.csv"))


needs_data = pytest.mark.skipif(not _real_files(), reason=f"no TEE data in {TEE_DIR}")


def _synthetic_csv(path: Path, n: int = 40, bend_sign: float = 1.0) -> None:
    """A file in the source's layout: the tip turns about a fixed axis in the base frame."""
    lines = [HEADER]
    axis = np.array([0.3, -0.5, 0.8])
    axis /= np.linalg.norm(axis)
    for i in range(n):
        steps = 1000 + 8 * i
        angle = np.radians(bend_sign * 0.5 * i)
        q_tip = np.concatenate([np.sin(angle / 2) * axis, [np.cos(angle / 2)]])
        cells = [str(i + 1), str(steps), str((-1) ** i * 3), "0", "0", "0",
                 *map(str, q_tip), "0", "0", "0", "0", "0", "0", "1"]
        lines.append(",".join(cells))
    path.write_text("\n".join(lines) + "\n")


def test_synthetic_file_gives_knob_degrees_amperes_and_tip_angle(tmp_path: Path) -> None:
    f = tmp_path / "motor1_synthetic.csv"
    _synthetic_csv(f)
    rec = load_tee_acquisition(f, steps_per_knob_deg=8.0)
    assert rec["q1"][0] == 0.0
    np.testing.assert_allclose(rec["pos1"], np.arange(40) * 1.0)
    np.testing.assert_allclose(rec["tip1"], np.arange(40) * 0.5, atol=1e-9)
    np.testing.assert_allclose(rec["cur1"][:2], [3 * CURRENT_A_PER_RAW, -3 * CURRENT_A_PER_RAW])
    for col in ("q2", "cmd2", "pos2", "cur2", "tip2"):
        assert np.all(rec[col] == 0.0)
    assert rec.metadata["knob"] == "1"


def test_tip_angle_is_signed_to_increase_with_the_knob(tmp_path: Path) -> None:
    f = tmp_path / "motor2_synthetic.csv"
    _synthetic_csv(f, bend_sign=-1.0)
    rec = load_tee_acquisition(f, steps_per_knob_deg=8.0)
    assert rec.metadata["knob"] == "2"
    assert np.corrcoef(rec["tip2"], rec["q2"])[0, 1] > 0.99
    assert np.all(rec["q1"] == 0.0)


def test_knob_cannot_be_guessed_from_an_unknown_name(tmp_path: Path) -> None:
    f = tmp_path / "acq.csv"
    _synthetic_csv(f)
    with pytest.raises(RecordingError, match="knob"):
        load_tee_acquisition(f)
    assert load_tee_acquisition(f, knob=2).metadata["knob"] == "2"


@pytest.mark.parametrize(("mutate", "message"), [
    (lambda text: text.replace("Current", "Courant"), "missing column"),
    (lambda text: text.replace(",1008,", ",abc,", 1), "not a number"),
    (lambda text: text.replace(",1008,", ",nan,", 1), "'Motor position'"),
    (lambda text: "\n".join(text.splitlines()[:5]), "data rows"),
    (lambda text: text.replace("\n3,", "\n3,1,", 1), "cells"),
    (lambda text: "", "empty"),
])
def test_malformed_file_is_refused_with_the_reason(tmp_path: Path, mutate, message) -> None:
    good = tmp_path / "good.csv"
    _synthetic_csv(good)
    bad = tmp_path / "motor1_bad.csv"
    bad.write_text(mutate(good.read_text()))
    with pytest.raises(RecordingError, match=message):
        load_tee_acquisition(bad)


def test_non_unit_quaternion_is_refused(tmp_path: Path) -> None:
    f = tmp_path / "motor1_q.csv"
    _synthetic_csv(f)
    lines = f.read_text().splitlines()
    cells = lines[3].split(",")
    cells[-1] = "5"
    lines[3] = ",".join(cells)
    f.write_text("\n".join(lines))
    with pytest.raises(RecordingError, match="unit quaternion"):
        load_tee_acquisition(f)


def test_missing_file_is_a_recording_error(tmp_path: Path) -> None:
    with pytest.raises(RecordingError, match="cannot read"):
        load_tee_acquisition(tmp_path / "motor1_nothing.csv")


@needs_data
@pytest.mark.realdata
@pytest.mark.parametrize("path", _real_files(), ids=lambda p: p.name)
def test_real_acquisition_converts_and_round_trips(path: Path, tmp_path: Path) -> None:
    rec = load_tee_acquisition(path)
    knob = int(rec.metadata["knob"])
    q = rec[f"q{knob}"]
    tip = rec[f"tip{knob}"]
    assert len(rec) > 1000
    # The sweep covers hundreds of steps and the tip follows it (the bending angle is real).
    assert np.ptp(q) * DEFAULT_STEPS_PER_KNOB_DEG > 1000
    assert np.corrcoef(tip, q)[0, 1] > 0.9
    assert 40.0 < np.ptp(tip) < 150.0
    assert np.max(np.abs(rec[f"cur{knob}"])) < 0.5
    out = tmp_path / "rec.csv"
    write_recording(out, rec)
    back = read_recording(out)
    np.testing.assert_allclose(back[f"tip{knob}"], tip)


@needs_data
@pytest.mark.realdata
def test_real_acquisition_goes_through_the_identification() -> None:
    path = _real_files()[0]
    point = identify_recording(load_tee_acquisition(path), source=path.name)
    assert point.knob == int(path.name[5]) - 1
    assert point.result.values["backlash_pos_deg"]  # one reversal at the top: one value
