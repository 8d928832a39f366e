"""Per-tick recordings: a CSV file with ``# key: value`` metadata lines first.

The format is specified in docs/recording-format.md. Reading validates and names the problem;
it never returns half a recording.
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

import numpy as np
from numpy.typing import NDArray

from tsmd.errors import TsmdError

REQUIRED_COLUMNS: tuple[str, ...] = (
    "t", "q1", "q2", "cmd1", "cmd2", "pos1", "pos2", "cur1", "cur2", "tip1", "tip2",
)
"""Columns every recording has, in this order; ``tip1``/``tip2`` may be empty (no tracker)."""

OPTIONAL_EMPTY: frozenset[str] = frozenset({"tip1", "tip2"})


class RecordingError(TsmdError, ValueError):
    """A recording file is not in the documented format; the message says where and why."""


@dataclass
class Recording:
    """Columns as float arrays of equal length (NaN where a cell was empty) plus metadata."""

    columns: dict[str, NDArray[np.float64]]
    metadata: dict[str, str] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.columns["t"]) if "t" in self.columns else 0

    def __getitem__(self, name: str) -> NDArray[np.float64]:
        try:
            return self.columns[name]
        except KeyError:
            raise RecordingError(f"recording has no column {name!r}") from None

    @property
    def has_tip(self) -> bool:
        """True when both tip columns hold measurements (a tracker was present)."""
        return all(
            name in self.columns and bool(np.isfinite(self.columns[name]).any())
            for name in ("tip1", "tip2")
        )

    def slice(self, start: int, stop: int) -> Recording:
        """Rows ``start:stop`` as a new recording with the same metadata."""
        return Recording({k: v[start:stop].copy() for k, v in self.columns.items()},
                         dict(self.metadata))


def _format(value: float) -> str:
    if math.isnan(value):
        return ""
    return repr(float(value))


def write_metadata(stream: IO[str], metadata: Mapping[str, object]) -> None:
    for key, value in metadata.items():
        if not key or ":" in key or "\n" in key:
            raise RecordingError(f"metadata key {key!r} must be non-empty, without ':' or newline")
        text = str(value)
        if "\n" in text:
            raise RecordingError(f"metadata value for {key!r} must be one line")
        stream.write(f"# {key}: {text}\n")


class RecordingWriter:
    """Streams rows to a CSV file; the control loop hands it one row per tick.

    Rows are buffered by the file object and flushed on :meth:`flush` and :meth:`close`, so a
    stopped daemon loses at most what the last flush did not reach the disk.
    """

    def __init__(self, path: str | os.PathLike[str], metadata: Mapping[str, object],
                 extra_columns: Sequence[str] = ()) -> None:
        self.path = Path(path)
        self.columns: tuple[str, ...] = REQUIRED_COLUMNS + tuple(extra_columns)
        if len(set(self.columns)) != len(self.columns):
            raise RecordingError(f"duplicate column names in {self.columns}")
        self._file: IO[str] = open(self.path, "w", newline="", encoding="utf-8")  # noqa: SIM115
        write_metadata(self._file, metadata)
        self._file.write(",".join(self.columns) + "\n")

    def write_row(self, values: Sequence[float]) -> None:
        if len(values) != len(self.columns):
            raise RecordingError(f"row has {len(values)} values, expected {len(self.columns)}")
        self._file.write(",".join(_format(v) for v in values) + "\n")

    def flush(self) -> None:
        self._file.flush()
        os.fsync(self._file.fileno())

    def close(self) -> None:
        if not self._file.closed:
            self.flush()
            self._file.close()

    def __enter__(self) -> RecordingWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def write_recording(path: str | os.PathLike[str], recording: Recording) -> None:
    """Write a whole recording (required columns first, then the others in their order)."""
    extra = [c for c in recording.columns if c not in REQUIRED_COLUMNS]
    n = len(recording)
    cols = []
    for name in (*REQUIRED_COLUMNS, *extra):
        col = recording.columns.get(name)
        if col is None:
            if name in OPTIONAL_EMPTY:
                col = np.full(n, np.nan)
            else:
                raise RecordingError(f"recording has no column {name!r}")
        if len(col) != n:
            raise RecordingError(f"column {name!r} has {len(col)} rows, expected {n}")
        cols.append(np.asarray(col, dtype=float))
    with RecordingWriter(path, recording.metadata, extra) as writer:
        for row in zip(*cols, strict=True):
            writer.write_row(row)


def read_recording(path: str | os.PathLike[str],
                   required: Iterable[str] = REQUIRED_COLUMNS) -> Recording:
    """Read and validate a recording; raise :class:`RecordingError` naming file, line and column."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as exc:
        raise RecordingError(f"{p}: cannot read: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise RecordingError(f"{p}: not UTF-8 text ({exc.reason})") from exc
    return parse_recording(text, source=str(p), required=required)


def parse_recording(text: str, source: str = "<recording>",
                    required: Iterable[str] = REQUIRED_COLUMNS) -> Recording:
    lines = text.splitlines()
    metadata: dict[str, str] = {}
    i = 0
    while i < len(lines) and (lines[i].startswith("#") or not lines[i].strip()):
        line = lines[i]
        if line.startswith("#"):
            key, sep, value = line[1:].partition(":")
            if not sep or not key.strip():
                raise RecordingError(f"{source}:{i + 1}: metadata line must be '# key: value'")
            metadata[key.strip()] = value.strip()
        i += 1
    if i >= len(lines):
        raise RecordingError(f"{source}: no header row")
    header = [h.strip() for h in next(csv.reader([lines[i]]))]
    header_line = i + 1
    if len(set(header)) != len(header):
        raise RecordingError(f"{source}:{header_line}: duplicate column names")
    missing = [c for c in required if c not in header]
    if missing:
        raise RecordingError(f"{source}:{header_line}: missing column(s) {', '.join(missing)}")
    rows: list[list[float]] = []
    reader = csv.reader(io.StringIO("\n".join(lines[i + 1:])))
    for offset, row in enumerate(reader):
        lineno = header_line + 1 + offset
        if not row or all(not cell.strip() for cell in row):
            continue
        if len(row) != len(header):
            raise RecordingError(
                f"{source}:{lineno}: {len(row)} cells, header has {len(header)}")
        values: list[float] = []
        for name, cell in zip(header, row, strict=True):
            stripped = cell.strip()
            if not stripped:
                values.append(math.nan)
                continue
            try:
                number = float(stripped)
            except ValueError:
                raise RecordingError(
                    f"{source}:{lineno}: column {name!r}: {stripped!r} is not a number") from None
            if math.isinf(number):
                raise RecordingError(f"{source}:{lineno}: column {name!r} is infinite")
            values.append(number)
        rows.append(values)
    if not rows:
        raise RecordingError(f"{source}: no data rows")
    data = np.array(rows, dtype=float)
    columns = {name: data[:, j].copy() for j, name in enumerate(header)}
    for name in required:
        if name in OPTIONAL_EMPTY:
            continue
        bad = np.flatnonzero(~np.isfinite(columns[name]))
        if bad.size:
            raise RecordingError(
                f"{source}:{header_line + 1 + int(bad[0])}: column {name!r} is empty or NaN")
    t = columns.get("t")
    if t is not None and len(t) > 1 and np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise RecordingError(f"{source}: column 't' is not strictly increasing at row {k + 2}")
    return Recording(columns, metadata)


def write_trajectory(path: str | os.PathLike[str], trajectory: Recording) -> None:
    """Write a trajectory file (``t,q1,q2`` first, then any other columns, e.g. a label)."""
    names = ["t", "q1", "q2"] + [c for c in trajectory.columns if c not in ("t", "q1", "q2")]
    missing = [c for c in names[:3] if c not in trajectory.columns]
    if missing:
        raise RecordingError(f"trajectory has no column(s) {', '.join(missing)}")
    with open(path, "w", newline="", encoding="utf-8") as stream:
        write_metadata(stream, trajectory.metadata)
        stream.write(",".join(names) + "\n")
        for row in zip(*(np.asarray(trajectory.columns[c], dtype=float) for c in names),
                       strict=True):
            stream.write(",".join(_format(v) for v in row) + "\n")


def read_trajectory(path: str | os.PathLike[str]) -> Recording:
    """A trajectory file for replay: columns ``t,q1,q2`` (deg), metadata lines allowed."""
    return read_recording(path, required=("t", "q1", "q2"))
