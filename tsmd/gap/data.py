"""Validated arrays taken from recordings, and the train/held-out split into time blocks."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from tsmd.gap.errors import GapError
from tsmd.gap.protocol import Segment, decode_table
from tsmd.gap.simulate import turning_points
from tsmd.recording import Recording

MIN_ROWS = 100
"""Fewer rows than this per recording cannot be split into train and held-out blocks."""

MIN_BLOCKS = 6
"""The diagnosis needs at least this many time blocks over all recordings (train + held-out)."""


@dataclass(frozen=True)
class GapSeries:
    """One recording reduced to what the diagnosis uses, all rows finite.

    ``knob_deg`` is the actual knob angle (``pos``; ``cmd`` when the drive gave no position):
    the motion that is replayed through the simulator.
    """

    name: str
    t_s: NDArray[np.float64]
    knob_deg: NDArray[np.float64]
    current_A: NDArray[np.float64]
    tip_deg: NDArray[np.float64]
    knob_source: str
    channel_valid: tuple[bool, bool, bool, bool] = (True, True, True, True)
    """Per channel (tip1, tip2, cur1, cur2): False when it never changes in this recording
    (a sensor that was not connected); such a channel is left out of fits and scores."""
    config: str = ""
    """Sheath shape / configuration label from the header (``configuration`` or
    ``sheath_shape``); recordings with different labels let curvature be told from friction."""
    catheter: str = ""
    """Catheter id from the header (``catheter``), for the report."""
    segment: NDArray[np.int64] | None = None
    """Matched-condition protocol (:mod:`tsmd.gap.protocol`): per row the index into
    ``segments`` (-1 outside the matched windows); None when the recording carries none."""
    segments: tuple[Segment, ...] = ()

    def __len__(self) -> int:
        return len(self.t_s)

    @property
    def duration_s(self) -> float:
        return float(self.t_s[-1] - self.t_s[0])


def _column(rec: Recording, name: str, source: str) -> NDArray[np.float64] | None:
    col = rec.columns.get(name)
    if col is None:
        return None
    arr = np.asarray(col, dtype=float)
    if arr.ndim != 1 or len(arr) != len(rec.columns.get("t", arr)):
        raise GapError(f"{source}: column {name!r} has the wrong length")
    return arr


def _require_finite(arr: NDArray[np.float64], name: str, source: str) -> None:
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise GapError(
            f"{source}: column {name!r} has {bad.size} empty/NaN value(s), first at data row "
            f"{int(bad[0]) + 1}; tsmd gap needs every row measured (cut the recording or fill it)")


def series_from_recording(rec: Recording, name: str) -> GapSeries:
    """Check a recording and take the columns the diagnosis needs; raise :class:`GapError`."""
    cols: dict[str, NDArray[np.float64]] = {}
    for col in ("t", "cur1", "cur2"):
        arr = _column(rec, col, name)
        if arr is None:
            raise GapError(f"{name}: missing column {col!r} (needs t, pos1/pos2 or cmd1/cmd2, "
                           "cur1, cur2, tip1, tip2)")
        cols[col] = arr
    tips = [_column(rec, c, name) for c in ("tip1", "tip2")]
    if any(t is None or not np.isfinite(t).any() for t in tips):
        raise GapError(f"{name}: no tip measurement (columns tip1/tip2 missing or empty); the gap "
                       "is measured against the tip angle, record with a tracker")
    knob_source = "pos"
    knob = [_column(rec, c, name) for c in ("pos1", "pos2")]
    if any(k is None or not np.isfinite(k).any() for k in knob):
        knob_source = "cmd"
        knob = [_column(rec, c, name) for c in ("cmd1", "cmd2")]
        if any(k is None for k in knob):
            raise GapError(f"{name}: missing knob motion: needs pos1/pos2 (actual) or cmd1/cmd2")
    n = len(cols["t"])
    if n < MIN_ROWS:
        raise GapError(f"{name}: too short: {n} rows, needs at least {MIN_ROWS}")
    arrays = {"t": cols["t"], "cur1": cols["cur1"], "cur2": cols["cur2"],
              f"{knob_source}1": knob[0], f"{knob_source}2": knob[1],
              "tip1": tips[0], "tip2": tips[1]}
    for col, arr in arrays.items():
        assert arr is not None
        _require_finite(arr, col, name)
    t = cols["t"]
    if np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise GapError(f"{name}: column 't' is not strictly increasing at data row {k + 2}")
    assert knob[0] is not None and knob[1] is not None
    assert tips[0] is not None and tips[1] is not None
    valid = tuple(bool(np.ptp(c) > 0) for c in (tips[0], tips[1], cols["cur1"], cols["cur2"]))
    if not (valid[0] or valid[1]):
        raise GapError(f"{name}: tip1 and tip2 never change: no tip measurement to compare with")
    segment, table = _protocol_columns(rec, name)
    return GapSeries(
        name=name, t_s=t.copy(),
        knob_deg=np.column_stack([knob[0], knob[1]]),
        current_A=np.column_stack([cols["cur1"], cols["cur2"]]),
        tip_deg=np.column_stack([tips[0], tips[1]]),
        knob_source=knob_source, channel_valid=valid,  # type: ignore[arg-type]
        config=condition_label(rec.metadata), catheter=rec.metadata.get("catheter", ""),
        segment=segment, segments=table)


def _protocol_columns(rec: Recording, name: str) -> tuple[NDArray[np.int64] | None,
                                                           tuple[Segment, ...]]:
    """The ``segment`` column and the ``segments`` header, checked against each other."""
    col = _column(rec, "segment", name)
    text = rec.metadata.get("segments", "").strip()
    if col is None and not text:
        return None, ()
    if col is None or not text:
        raise GapError(f"{name}: a matched-condition recording needs both the 'segment' column "
                       "and the 'segments' header line")
    table = tuple(decode_table(text, name))
    if not np.all(np.isfinite(col)) or np.any(col != np.round(col)) or np.any(col < -1) or \
            np.any(col >= len(table)):
        raise GapError(f"{name}: column 'segment' must hold whole numbers -1..{len(table) - 1} "
                       "(indices into the 'segments' header)")
    return col.astype(np.int64), table


CONFIG_KEYS: tuple[str, ...] = ("configuration", "sheath_shape")
"""Header keys naming the condition a recording was taken in (first one present wins)."""


def condition_label(metadata: dict[str, str]) -> str:
    """The recording's configuration label from its header, '' when it has none."""
    return next((metadata[k].strip() for k in CONFIG_KEYS if metadata.get(k, "").strip()), "")


@dataclass(frozen=True)
class Split:
    """Per series: block index of every row and whether the row is held out."""

    block: tuple[NDArray[np.int64], ...]
    held_out: tuple[NDArray[np.bool_], ...]
    block_s: float
    description: str

    @property
    def n_blocks(self) -> int:
        return int(sum(int(b.max()) + 1 for b in self.block))

    def test_blocks(self) -> list[tuple[int, NDArray[np.bool_]]]:
        """(series index, row mask) for every held-out block: the units of the bootstrap."""
        out = []
        for i, (blk, ho) in enumerate(zip(self.block, self.held_out, strict=True)):
            for b in np.unique(blk[ho]):
                out.append((i, (blk == b) & ho))
        return out


def parse_holdout(text: str) -> float | list[str]:
    """``0.3`` = that fraction of interleaved time blocks; otherwise comma-separated names."""
    try:
        frac = float(text)
    except ValueError:
        names = [s.strip() for s in text.split(",") if s.strip()]
        if not names:
            raise GapError(
                f"--holdout {text!r}: give a fraction like 0.3 or recording names") from None
        return names
    if not 0.05 <= frac <= 0.6:
        raise GapError(f"--holdout {frac}: the held-out fraction must be in 0.05..0.6")
    return frac


def make_split(series: Sequence[GapSeries], holdout: float | Sequence[str] = 0.3,
               block_s: float | None = None) -> Split:
    """Cut every series into time blocks and hold some out, never seen by any fit.

    A fraction ``f`` holds out every ``round(1/f)``-th block (interleaved, so train and held-out
    data cover the same motions); names hold out whole recordings (their blocks are still the
    bootstrap units).
    """
    if not series:
        raise GapError("no recordings given")
    total_s = sum(s.duration_s for s in series)
    if block_s is None:
        block_s = max(total_s / 48.0, 1.0)
    if block_s <= 0:
        raise GapError(f"block length {block_s} s must be positive")
    blocks: list[NDArray[np.int64]] = []
    for s in series:
        rel = s.t_s - s.t_s[0]
        nb = max(round(s.duration_s / block_s), 1)
        blk = np.minimum((rel / (s.duration_s + 1e-12) * nb).astype(np.int64), nb - 1)
        blocks.append(blk)
    held: list[NDArray[np.bool_]] = []
    if isinstance(holdout, float):
        period = max(round(1.0 / holdout), 2)
        counter = 0
        for blk in blocks:
            nb = int(blk.max()) + 1
            chosen = [(counter + b) % period == period - 1 for b in range(nb)]
            counter += nb
            held.append(np.asarray(chosen, dtype=bool)[blk])
        desc = f"1 time block in {period} held out (blocks of {block_s:.1f} s, interleaved)"
    else:
        names = {s.name for s in series}
        unknown = [n for n in holdout if n not in names]
        if unknown:
            raise GapError(f"--holdout names {unknown} match no recording ({sorted(names)})")
        held = [np.full(len(s), s.name in holdout) for s in series]
        desc = f"recordings {', '.join(holdout)} held out whole; blocks of {block_s:.1f} s"
    split = Split(tuple(blocks), tuple(held), float(block_s), desc)
    n_test = sum(int(h.any()) for h in held)
    if split.n_blocks < MIN_BLOCKS:
        raise GapError(f"recordings too short: {split.n_blocks} time blocks of {block_s:.1f} s, "
                       f"needs at least {MIN_BLOCKS}")
    if n_test == 0 or all(h.all() for h in held):
        raise GapError("the split leaves no training or no held-out data")
    for c, channel in enumerate(("tip1", "tip2", "cur1", "cur2")):
        tested = [s.name for s, h in zip(series, held, strict=True)
                  if s.channel_valid[c] and h.any()]
        trained = any(s.channel_valid[c] and not h.all() for s, h in zip(series, held,
                                                                         strict=True))
        if tested and not trained:
            raise GapError(f"{channel} is measured in the held-out data ({', '.join(tested)}) "
                           "but in no training row: nothing to fit it on; hold out other data")
    if not any(s.channel_valid[c] and h.any() for s, h in zip(series, held, strict=True)
               for c in (0, 1)):
        raise GapError("the held-out data have no tip measurement (tip1 and tip2 never change "
                       "there): nothing to score the gap on; hold out other data")
    n_test_blocks = len(split.test_blocks())
    if n_test_blocks < 3:
        raise GapError(f"only {n_test_blocks} held-out blocks: too few for a confidence interval")
    return split


def fit_windows(series: Sequence[GapSeries], split: Split, window_s: float,
                n_windows: int) -> tuple[list[GapSeries], Split]:
    """A segment-subsampled copy for the physics base fit: ``n_windows`` stretches of
    ``window_s`` spread evenly over the recordings (at least one per recording).

    Knob motion is slow against 250 Hz and a few plant constants are set by a few minutes of
    varied motion as well as by half an hour, so the base fit need not replay every minute.
    Each window is simulated from a reset plant; its rows up to the last knob's first reversal
    (the hysteresis state is unknown before it) are marked held out, i.e. not fitted on.
    Recordings short enough are returned whole.
    """
    total_s = sum(s.duration_s for s in series)
    if total_s <= 1.5 * window_s * n_windows:
        return list(series), split
    out: list[GapSeries] = []
    blocks, held = [], []
    for s, blk, ho in zip(series, split.block, split.held_out, strict=True):
        k = max(round(n_windows * s.duration_s / total_s), 1)
        starts = s.t_s[0] + (np.arange(k) + 0.5) * s.duration_s / k - 0.5 * window_s
        for i, t0 in enumerate(np.clip(starts, s.t_s[0], max(s.t_s[-1] - window_s, s.t_s[0]))):
            rows = np.flatnonzero((s.t_s >= t0) & (s.t_s < t0 + window_s))
            if len(rows) < MIN_ROWS:
                continue
            knob = s.knob_deg[rows]
            first = [turning_points(knob[:, j], 0.5) for j in range(2)]
            warm = max((int(f[0]) if len(f) else len(rows) // 3) for f in first)
            mask = ho[rows].copy()
            mask[:warm] = True
            out.append(GapSeries(f"{s.name}[window {i}]", s.t_s[rows], knob,
                                 s.current_A[rows], s.tip_deg[rows], s.knob_source,
                                 s.channel_valid, s.config, s.catheter))
            blocks.append(blk[rows])
            held.append(mask)
    if not out or all(h.all() for h in held):
        return list(series), split
    desc = f"{len(out)} windows of {window_s:.0f} s for the physics base fit"
    return out, Split(tuple(blocks), tuple(held), split.block_s, desc)

