"""Where the loop's per-tick rows go: memory (replay, tests) or a file written off the hot path."""

from __future__ import annotations

import collections
import threading

from tsmd.recording import RecordingWriter


class MemoryRecorder:
    """Keeps every row in memory (replay, tests)."""

    def __init__(self) -> None:
        self.rows: list[tuple[float, ...]] = []

    def append(self, row: tuple[float, ...]) -> None:
        self.rows.append(row)


class BackgroundRecorder:
    """Per-tick rows to a recording file, written by a thread every ``flush_interval_s``.

    The hot path only appends a tuple to a deque; formatting, writing and fsync happen in the
    writer thread. :meth:`close` writes what is left, so a clean stop loses nothing.
    """

    def __init__(self, path: str, metadata: dict[str, object], flush_interval_s: float,
                 extra_columns: tuple[str, ...] = ()) -> None:
        self.path = path
        self._writer = RecordingWriter(path, metadata, extra_columns)
        self._rows: collections.deque[tuple[float, ...]] = collections.deque()
        self._interval_s = flush_interval_s
        self._stop = threading.Event()
        self.rows_written = 0
        self._thread = threading.Thread(target=self._run, name="tsmd-recorder", daemon=True)
        self._thread.start()

    def append(self, row: tuple[float, ...]) -> None:
        self._rows.append(row)

    def _drain(self) -> None:
        rows = self._rows
        while rows:
            self._writer.write_row(rows.popleft())
            self.rows_written += 1
        self._writer.flush()

    def _run(self) -> None:
        while not self._stop.wait(self._interval_s):
            self._drain()

    def close(self) -> None:
        self._stop.set()
        self._thread.join()
        self._drain()
        self._writer.close()
