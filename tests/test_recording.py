"""The recording format (docs/recording-format.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tsmd.recording import (
    REQUIRED_COLUMNS,
    Recording,
    RecordingError,
    read_recording,
    read_trajectory,
    write_recording,
)


def _recording(n: int = 5, tip: bool = True) -> Recording:
    t = np.arange(n) * 0.004
    cols = {name: np.linspace(0, 1, n) + k for k, name in enumerate(REQUIRED_COLUMNS)}
    cols["t"] = t
    if not tip:
        cols["tip1"] = np.full(n, np.nan)
        cols["tip2"] = np.full(n, np.nan)
    cols["extra"] = np.ones(n)
    return Recording(cols, {"catheter": "sim-001", "rate_hz": "250"})


def test_round_trip_keeps_columns_values_and_metadata(tmp_path: Path) -> None:
    rec = _recording()
    write_recording(tmp_path / "r.csv", rec)
    back = read_recording(tmp_path / "r.csv")
    assert back.metadata == rec.metadata
    assert list(back.columns) == [*REQUIRED_COLUMNS, "extra"]
    for name, col in rec.columns.items():
        np.testing.assert_array_equal(back[name], col)


def test_empty_tip_columns_read_as_nan_and_has_tip_is_false(tmp_path: Path) -> None:
    write_recording(tmp_path / "r.csv", _recording(tip=False))
    back = read_recording(tmp_path / "r.csv")
    assert np.isnan(back["tip1"]).all()
    assert not back.has_tip


def test_missing_column_is_named(tmp_path: Path) -> None:
    (tmp_path / "r.csv").write_text("t,q1,q2\n0,1,2\n")
    with pytest.raises(RecordingError, match="missing column.*cmd1"):
        read_recording(tmp_path / "r.csv")


def test_non_number_cell_names_line_and_column(tmp_path: Path) -> None:
    (tmp_path / "tr.csv").write_text("# a: b\nt,q1,q2\n0,1,2\n0.1,x,2\n")
    with pytest.raises(RecordingError, match=r"tr.csv:4: column 'q1'"):
        read_trajectory(tmp_path / "tr.csv")


def test_nan_in_required_column_is_refused(tmp_path: Path) -> None:
    (tmp_path / "tr.csv").write_text("t,q1,q2\n0,1,2\n0.1,,2\n")
    with pytest.raises(RecordingError, match="'q1' is empty or NaN"):
        read_trajectory(tmp_path / "tr.csv")


def test_time_must_increase(tmp_path: Path) -> None:
    (tmp_path / "tr.csv").write_text("t,q1,q2\n0,1,2\n0,1,2\n")
    with pytest.raises(RecordingError, match="not strictly increasing"):
        read_trajectory(tmp_path / "tr.csv")


def test_ragged_row_is_refused(tmp_path: Path) -> None:
    (tmp_path / "tr.csv").write_text("t,q1,q2\n0,1\n")
    with pytest.raises(RecordingError, match="2 cells, header has 3"):
        read_trajectory(tmp_path / "tr.csv")


def test_unreadable_file_is_a_recording_error(tmp_path: Path) -> None:
    with pytest.raises(RecordingError, match="cannot read"):
        read_recording(tmp_path / "absent.csv")
