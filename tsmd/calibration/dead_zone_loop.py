"""The dead-zone loop: each unit's plateau gap, read from motor current (session 25).

Where a product's tip rests in the dead zone (its plateau, the height the joints' friction
holds it at) scatters from unit to unit, the calibration's sweeps do not show it: the loaded
current reads the edge, where the rope takes load, not the level the tip stood at. A loop into
the dead zone does (docs/model.md, session 24 "s24-snake", point 2): from one side's amplitude
back to 0 the rope on that side slackens with the tip on *its own* side's plateau; going out
again it takes load at the same rope length, a loading edge. The full cycle's edge on that side
is where the same rope takes load with the tip on the *other* side's plateau. The loop's edge
minus the full cycle's is the plateau gap: twice the plateau over the release's kinematic
slope. A unit whose gap is the data-sheet unit's has the sheet's plateau; each degree more moves
its plateaus out by the sheet's ``plateau_gap_factor / 2`` (tracked flats over gap on the
sheet's unit, :mod:`tsmd.datasheet_plateau_gap`).

The move (per knob, the other at 0): 0 -> -A, then ``LOOPS_PER_SIDE`` times -A -> 0 -> -A
(the negative loops), -A -> +A (the full cycle's positive edge), ``LOOPS_PER_SIDE`` times
+A -> 0 -> +A, +A -> -A (the full cycle's negative edge), -A -> 0. Every edge is read by the
calibration's own half-cycle analysis (:func:`tsmd.calibration.identify.analyse_half_cycle`:
its edge fit, ripple-removed as the product's options say), so a reader's bias cancels in the
gap; the gap is the median over every loop of both sides (the prototype's one loop per side
scattered 2.3 deg between sides).
"""

from __future__ import annotations

import itertools
import math
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from tsmd.calibration.errors import CalibrationCancelledError, CalibrationError
from tsmd.calibration.identify import analyse_half_cycle, split_half_cycles
from tsmd.calibration.options import IdentifyOptions
from tsmd.calibration.protocol import move_trajectory, return_to_zero
from tsmd.calibration.signal import condition
from tsmd.errors import TsmdError
from tsmd.recording import Recording
from tsmd.trajectory import TrajectoryRunner

FloatArray = NDArray[np.float64]

LOOPS_PER_SIDE = 2
"""Loops into the dead zone per side and knob (each gives one loading edge)."""
LOOP_AMPLITUDE_DEG = 90.0
"""The loops start and end at the sweep's amplitude (the release a sweep has)."""
LOOP_SPEED_DEG_S = 2.0 * math.pi * 0.06 * 90.0
"""Peak knob speed of each leg: the fast protocol's sine at its amplitude (34 deg/s). One
constant for every unit and the sheet's, whatever protocol swept them: the edges' reading moves
with speed, and only a gap read at one speed compares with the sheet's."""
INWARD_SHARE = 0.5
"""A half-cycle starting within this share of the amplitude from 0 is a loop's way out."""


@dataclass(frozen=True)
class LoopMove:
    """One knob's loop move: commanded angles at the runner's ticks, both knobs."""

    knob: int
    t_s: FloatArray
    q_deg: FloatArray

    @property
    def duration_s(self) -> float:
        return float(self.t_s[-1]) if self.t_s.size else 0.0


def loop_points(amplitude_deg: float = LOOP_AMPLITUDE_DEG,
                loops: int = LOOPS_PER_SIDE) -> list[float]:
    """The knob's turning points, from 0 back to 0 (see the module's docstring)."""
    a = float(amplitude_deg)
    return [0.0, -a, *([0.0, -a] * loops), a, *([0.0, a] * loops), -a, 0.0]


def loop_move(knob: int, period_s: float, amplitude_deg: float = LOOP_AMPLITUDE_DEG,
              loops: int = LOOPS_PER_SIDE, speed_deg_s: float = LOOP_SPEED_DEG_S) -> LoopMove:
    """The move of ``knob`` from 0 through its loops back to 0, the other knob held at 0: one
    raised-cosine leg per pair of turning points at ``speed_deg_s`` peak."""
    points = loop_points(amplitude_deg, loops)
    legs = []
    for a, b in itertools.pairwise(points):
        start, end = np.zeros(2), np.zeros(2)
        start[knob], end[knob] = a, b
        legs.append(move_trajectory(start, end, period_s, speed_deg_s))
    q = np.concatenate(legs)
    t = np.arange(1, len(q) + 1, dtype=float) * float(period_s)
    return LoopMove(knob, t, q)


@dataclass(frozen=True)
class LoopEdges:
    """The edges (knob deg, signed) one loop move showed: each loop's way out per side and the
    full cycle's half-cycle per side."""

    loop_pos_deg: tuple[float, ...]
    loop_neg_deg: tuple[float, ...]
    full_pos_deg: tuple[float, ...]
    full_neg_deg: tuple[float, ...]

    @property
    def gap_pos_deg(self) -> float:
        """Loop edge minus the full cycle's on the positive side (NaN: a side not read)."""
        return _mean(self.loop_pos_deg) - _mean(self.full_pos_deg)

    @property
    def gap_neg_deg(self) -> float:
        return _mean(self.full_neg_deg) - _mean(self.loop_neg_deg)

    @property
    def loop_gaps_deg(self) -> tuple[float, ...]:
        """Each loop's gap: its edge against its side's full-cycle edge (a side without a
        full-cycle edge, or a loop without an edge, gives none). A gap that is not positive is
        no reading: with the tip on its own side's plateau the rope takes load farther out
        than with it on the other side's, so an edge inside the full cycle's is a mis-read
        (snakedent development 4 phi2: the full cycle's negative edge fitted at -38.5 deg on a
        later knee, its loops at -31.5, gap -7 on that side against +11.6 on the other)."""
        full_pos, full_neg = _mean(self.full_pos_deg), _mean(self.full_neg_deg)
        gaps = [e - full_pos for e in self.loop_pos_deg] + [full_neg - e
                                                           for e in self.loop_neg_deg]
        return tuple(g for g in gaps if math.isfinite(g) and g > 0.0)

    @property
    def gap_deg(self) -> float:
        """The plateau gap: the median of every loop's gap, both sides (NaN: none read). Not
        the mean: one loop's edge fit now and then takes a later knee (snakedent development
        unit 8 phi2, one of 36 loops at 9 deg beyond its twin), and the median of four sets
        it aside (development units 1-8, their flats from the gap: rms 0.44 -> 0.29 deg)."""
        gaps = self.loop_gaps_deg
        return float(np.median(gaps)) if gaps else math.nan


def _mean(values: tuple[float, ...]) -> float:
    finite = [v for v in values if math.isfinite(v)]
    return float(np.mean(finite)) if finite else math.nan


def read_loop_edges(t_s: FloatArray, cmd_deg: FloatArray, pos_deg: FloatArray,
                    current_A: FloatArray, options: IdentifyOptions | None = None) -> LoopEdges:
    """Every loop's and full cycle's edge in one knob's loop move (commanded and actual angle,
    motor current), each half-cycle by the calibration's analysis with ``options``."""
    opts = options or IdentifyOptions()
    data = condition(np.asarray(t_s, float), np.asarray(cmd_deg, float),
                     np.asarray(pos_deg, float), np.asarray(current_A, float),
                     cutoff_hz=opts.cutoff_hz, order=opts.filter_order, max_gap_s=opts.max_gap_s)
    amplitude = float(np.nanmax(np.abs(data.cmd_deg)))
    found: dict[str, list[float]] = {"loop+": [], "loop-": [], "full+": [], "full-": []}
    for direction, a, b, after in split_half_cycles(data.cmd_deg, opts.min_reversal_deg):
        start, stop = float(data.cmd_deg[a]), float(data.cmd_deg[b - 1])
        if not after or direction * stop < (1.0 - INWARD_SHARE) * amplitude:
            continue  # the first leg, or a way in
        if abs(start) < INWARD_SHARE * amplitude:
            kind = "loop"
        elif direction * start < -(1.0 - INWARD_SHARE) * amplitude:
            kind = "full"
        else:
            continue
        h = analyse_half_cycle(data, direction, a, b, False, opts)
        found[f"{kind}{'+' if direction > 0 else '-'}"].append(h.edge_deg)
    return LoopEdges(*(tuple(found[k]) for k in ("loop+", "loop-", "full+", "full-")))


def plateau_shift_deg(gap_deg: float | None, sheet_gap_deg: float | None,
                      factor: float | None) -> float:
    """How far each plateau height moves out (deg; negative: in) for a unit whose loop read
    ``gap_deg`` under a sheet that read ``sheet_gap_deg`` with ``factor`` (tracked flats, both
    sides, over the gap): ``factor (gap - sheet gap) / 2``; 0 where any is missing."""
    if gap_deg is None or sheet_gap_deg is None or factor is None:
        return 0.0
    if not math.isfinite(gap_deg):
        return 0.0
    return 0.5 * float(factor) * (float(gap_deg) - float(sheet_gap_deg))


def wants_loop(device: Any) -> bool:
    """Whether the product's sheet opts in: a knob with both loop numbers."""
    return any(getattr(k, "plateau_gap_deg", None) is not None
               and getattr(k, "plateau_gap_factor", None) is not None for k in device.knobs)


@dataclass(frozen=True)
class LoopRun:
    """Both knobs' loop moves as played: the gaps read (None: that knob's not read), the
    recordings, the knobs' motion (s) and one note per knob for the calibration's report."""

    gaps_deg: tuple[float | None, float | None]
    recordings: tuple[Recording, ...]
    motion_s: float
    notes: tuple[str, ...]


def play_loops(runner: TrajectoryRunner, device: Any, options: Any,
               cancel: threading.Event | None = None,
               progress: Callable[[float, str], None] | None = None) -> LoopRun:
    """Play each opted-in knob's loop move from 0 (the other knob at 0) and read its gap; the
    knobs end at 0 whatever happens (a cancel raises CalibrationCancelledError, a fault
    CalibrationError). ``options``: the calibration's per-knob identification options."""
    period_s = runner.period_s
    gaps: list[float | None] = [None, None]
    recordings: list[Recording] = []
    notes: list[str] = []
    motion = 0.0
    for knob, sheet in enumerate(device.knobs):
        if getattr(sheet, "plateau_gap_deg", None) is None:
            continue
        move = loop_move(knob, period_s)
        name = f"phi{knob + 1}"
        if progress is not None:
            progress(1.0, f"dead-zone loop: {name} ({move.duration_s:.0f} s)")
        try:
            rec = runner.run(move.t_s, move.q_deg, False, cancel, None)
        except TsmdError as exc:
            _back_to_zero(runner, move.q_deg[0])
            raise CalibrationError(f"dead-zone loop {name}: {exc}") from None
        motion += len(rec) * period_s
        if (cancel is not None and cancel.is_set()) or len(rec) < len(move.q_deg):
            last = np.array([rec["cmd1"][-1], rec["cmd2"][-1]], float) if len(rec) else np.zeros(2)
            motion += _back_to_zero(runner, last)
            if cancel is not None and cancel.is_set():
                raise CalibrationCancelledError(f"cancelled during the dead-zone loop ({name})")
            raise CalibrationError(f"dead-zone loop {name}: the runner stopped after "
                                   f"{len(rec)} of {len(move.q_deg)} ticks")
        recordings.append(rec)
        opts = options[knob] if isinstance(options, tuple) else options
        k = knob + 1
        edges = read_loop_edges(np.asarray(rec["t"], float), np.asarray(rec[f"cmd{k}"], float),
                                np.asarray(rec[f"pos{k}"], float),
                                np.asarray(rec[f"cur{k}"], float), opts)
        gap = edges.gap_deg
        shift = plateau_shift_deg(gap, sheet.plateau_gap_deg, sheet.plateau_gap_factor)
        if math.isfinite(gap):
            gaps[knob] = gap
            notes.append(f"dead-zone loop {name}: plateau gap {gap:.2f} deg (sides "
                         f"{edges.gap_pos_deg:.2f} / {edges.gap_neg_deg:.2f}; the sheet's "
                         f"{sheet.plateau_gap_deg:.2f}): plateau heights moved out by "
                         f"{shift:+.2f} deg")
        else:
            notes.append(f"dead-zone loop {name}: no edge read on either side; the sheet's "
                         "plateau heights kept")
    return LoopRun((gaps[0], gaps[1]), tuple(recordings), motion, tuple(notes))


def _back_to_zero(runner: TrajectoryRunner, q_deg: FloatArray) -> float:
    """Both knobs smoothly back to 0 (never cancelled); the motion's seconds."""
    t, q = return_to_zero(np.asarray(q_deg, float), runner.period_s)
    runner.run(t, q, False, None, None)
    return len(q) * runner.period_s
